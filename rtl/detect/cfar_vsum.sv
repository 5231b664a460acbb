// SPDX-License-Identifier: Apache-2.0
// cfar_2d's vertical sums (stages 2..4 of its pipeline, docs/detect.md): from the column
// word of the last ROWS range rows (slot = row mod ROWS), the sums over the tested row's
// window rows and guard rows, and its CUT-row and range-neighbour cells. The slot masks
// rotate with the row, not the data.
`default_nettype none

module cfar_vsum #(
  parameter int ROWS = 14,        // column store slots (2*PR+2)
  parameter int NE = 13,          // window rows (2*PR+1)
  parameter int PR = 6,
  parameter int GUARD_R = 2,
  parameter int POW_W = 34,
  // Derived, do not override: the vertical sums' width (at most NE cells of POW_W bits,
  // NE odd) and the width of the stage-3 partial sums (at most 4 cells)
  parameter int VS_W = POW_W + $clog2(NE),
  parameter int P3_W = (VS_W < POW_W + 2) ? VS_W : POW_W + 2
) (
  input  wire logic                          clk,
  // stage 1: the slot written by the pass, window row k (row q-PR+k) exists
  input  wire logic [$clog2(ROWS)-1:0]       slot1,
  input  wire logic [NE-1:0]                 rowv1,
  // stage 2: the column word (slot s at bits s*POW_W); the slot masks of the window rows
  // (o) and guard rows (i) that exist
  input  wire logic [ROWS*POW_W-1:0]         cw2,
  output logic      [ROWS-1:0]               mo2,
  output logic      [ROWS-1:0]               mi2,
  // stage 4: vertical sums over the window rows (o) and guard rows (i), the cells of the
  // CUT's row and of rows q-1 (rm) and q+1 (rp)
  output logic      [VS_W-1:0]               vo4,
  output logic      [VS_W-1:0]               vi4,
  output logic      [POW_W-1:0]              vcut4,
  output logic      [POW_W-1:0]              rm4,
  output logic      [POW_W-1:0]              rp4
);

  localparam int SLOT_W = $clog2(ROWS);

  if (VS_W != POW_W + $clog2(NE) || P3_W != ((VS_W < POW_W + 2) ? VS_W : POW_W + 2) ||
      NE % 2 != 1) begin : g_bad_derived
    $fatal(1, "%m: VS_W/P3_W are derived, do not override (NE=%0d odd)", NE);
  end

  // Stage 2: slot masks. Window row k of the tested row sits in slot (slot+1+k) mod ROWS.
  logic [ROWS-1:0] mc2_q, mrm2_q, mrp2_q;
  always_ff @(posedge clk) begin
    for (int s = 0; s < ROWS; s++) begin
      mo2[s]   <= 1'b0;
      mi2[s]   <= 1'b0;
      mc2_q[s]   <= 1'b0;
      mrm2_q[s]  <= 1'b0;
      mrp2_q[s]  <= 1'b0;
      for (int k = 0; k < NE; k++)
        if (slot1 == SLOT_W'((s + ROWS - 1 - k) % ROWS)) begin
          mo2[s]  <= rowv1[k];
          mi2[s]  <= rowv1[k] && k >= PR - GUARD_R && k <= PR + GUARD_R;
          mc2_q[s]  <= (k == PR);
          mrm2_q[s] <= (k == PR - 1);
          mrp2_q[s] <= (k == PR + 1);
        end
    end
  end

  // Stage 3: masked slots summed in two adder levels (64 -> 16 terms of at most 4 cells;
  // slots beyond ROWS are constant zero), the CUT-row and range-neighbour cells selected
  // (AND-OR over slots). Every partial sum is one of masked cells, so no wider than the
  // whole sum (VS_W) nor than 4 cells (P3_W).
  logic [P3_W-1:0] po3_q [16], pi3_q [16];
  logic [POW_W-1:0] c3_q, rm3_q, rp3_q;
  always_ff @(posedge clk) begin
    logic [P3_W-1:0]  xo [64], xi [64];
    logic [POW_W-1:0] c, m, p, w;
    c = '0;
    m = '0;
    p = '0;
    for (int s = 0; s < 64; s++) begin
      xo[s] = '0;
      xi[s] = '0;
      if (s < ROWS) begin
        w = cw2[(s % ROWS) * POW_W +: POW_W];
        if (mo2[s % ROWS]) xo[s] = P3_W'(w);
        if (mi2[s % ROWS]) xi[s] = P3_W'(w);
        if (mc2_q[s % ROWS]) c = c | w;
        if (mrm2_q[s % ROWS]) m = m | w;
        if (mrp2_q[s % ROWS]) p = p | w;
      end
    end
    for (int i = 0; i < 32; i++) begin
      xo[i] = xo[2 * i] + xo[2 * i + 1];
      xi[i] = xi[2 * i] + xi[2 * i + 1];
    end
    for (int i = 0; i < 16; i++) begin
      po3_q[i] <= xo[2 * i] + xo[2 * i + 1];
      pi3_q[i] <= xi[2 * i] + xi[2 * i + 1];
    end
    c3_q  <= c;
    rm3_q <= m;
    rp3_q <= p;
  end

  // Stage 4: vertical sums complete (the remaining adder levels)
  always_ff @(posedge clk) begin
    logic [VS_W-1:0] xo [16], xi [16];
    for (int i = 0; i < 16; i++) begin
      xo[i] = VS_W'(po3_q[i]);
      xi[i] = VS_W'(pi3_q[i]);
    end
    for (int w = 8; w >= 1; w = w / 2)
      for (int i = 0; i < w; i++) begin
        xo[i] = xo[2 * i] + xo[2 * i + 1];
        xi[i] = xi[2 * i] + xi[2 * i + 1];
      end
    vo4    <= xo[0];
    vi4    <= xi[0];
    vcut4  <= c3_q;
    rm4    <= rm3_q;
    rp4    <= rp3_q;
  end

endmodule

`default_nettype wire
