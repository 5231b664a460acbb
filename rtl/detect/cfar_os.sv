// SPDX-License-Identifier: Apache-2.0
// cfar_2d's ordered-statistic test (OS-CFAR, docs/detect.md): the cell under test is
// detected when CUT > alpha * X_(k), X_(k) the k-th smallest training cell. That is exactly
// "at least k training cells X_i satisfy alpha * X_i < CUT", so no sorting: every training
// cell is compared with the CUT's threshold and the comparator bits are counted.
// With the inverse scale inv = 2^SCALE_FRAC / alpha (the cfg_scale entry of the row when
// the kind is OS, model/cfar_2d.py) the test per training cell is the exact integer
//   X_i * 2^SCALE_FRAC < CUT * inv  <=>  X_i <= T,  T = floor((CUT * inv - 1) / 2^SCALE_FRAC)
// (no training cell passes when CUT * inv = 0), so one product per cell, not per training
// cell. The window is cfar_2d's own (same guard and training cells as CA): the full column
// words of the last 2*PD columns are held here (the column store slots, not rotated: the
// training mask rotates with the slot instead, like cfar_2d's slot masks), and the
// threshold T of each column's CUT-row cell travels beside them, so T is ready when the
// CUT's window is complete PD columns later.
// Pipeline (cfar_2d's stages): 2 column word and slot masks in; 4 the window complete
// (the arriving column and the shift register); 5 comparator bits; 6-8 popcount;
// 9 count >= k(e). The threshold: 2 clocks of product (partial products, then the sum and
// T) on the column shifts, PD-2 shifts of delay.
`default_nettype none

module cfar_os #(
  parameter int ROWS = 14,        // column store slots (2*PR+2)
  parameter int NE = 13,          // edge indices (2*PR+1)
  parameter int PR = 6,
  parameter int PD = 10,
  parameter int GUARD_R = 2,
  parameter int GUARD_D = 2,
  parameter int POW_W = 34,
  parameter int CNT_W = 9,
  parameter int SCALE_W = 32,
  parameter int SCALE_FRAC = 20,
  // rank: k = OS_RANK / 1000 of the training cells, rounded half to even, at least 1
  parameter int OS_RANK = 750
) (
  input  wire logic                          clk,
  // stage 2: the column word (slot s at bits s*POW_W), slot masks of the window rows (o) and
  // guard rows (i), the row's edge index
  input  wire logic [ROWS*POW_W-1:0]         cw2,
  input  wire logic [ROWS-1:0]               mo2,
  input  wire logic [ROWS-1:0]               mi2,
  input  wire logic [$clog2(NE)-1:0]         e2,
  // stage 4: a tested row's column arrives (shift), its CUT-row cell
  input  wire logic                          ev4,
  input  wire logic [POW_W-1:0]              vcut4,
  // inverse threshold scale per edge index (quasi-static)
  input  wire logic [NE*SCALE_W-1:0]         cfg_scale,
  // stage 9: at least k training cells below the CUT's threshold
  output logic                               os9
);

  localparam int E_W  = $clog2(NE);
  localparam int NCOL = 2 * PD + 1;
  localparam int NC   = NCOL * ROWS;        // comparators
  localparam int G1   = (NC + 7) / 8;       // popcount groups after stage 6
  localparam int G2   = (G1 + 7) / 8;       // after stage 7

  if (PD < 2) begin : g_bad_pd
    $fatal(1, "%m: OS needs GUARD_D + TRAIN_D >= 2 (the threshold product takes 2 columns)");
  end
  if (OS_RANK < 1 || OS_RANK > 999) begin : g_bad_rank
    $fatal(1, "%m: OS_RANK=%0d not in 1..999 (per mille)", OS_RANK);
  end

  // k per edge index: training cells n(e) of the window cut at the range ends,
  // k = round_half_even(OS_RANK * n / 1000) in 1..n (model.cfar_2d.os_rank_k)
  // (results assigned to the function name, no `return`: Yosys reads the file as written)
  function automatic logic [NE*CNT_W-1:0] k_table();
    int lo, hi, n_out, n_in, n, q, r;
    k_table = '0;
    for (int e = 0; e < NE; e++) begin
      lo = (e < PR) ? PR - e : 0;
      hi = (e > PR) ? e - PR : 0;
      n_out = NE - lo - hi;
      n_in = 0;
      for (int k = PR - GUARD_R; k <= PR + GUARD_R; k++)
        if (k >= lo && k <= 2 * PR - hi) n_in++;
      n = n_out * (2 * PD + 1) - n_in * (2 * GUARD_D + 1);
      q = (OS_RANK * n) / 1000;
      r = (OS_RANK * n) % 1000;
      if (r > 500 || (r == 500 && q % 2 == 1)) q++;
      if (q < 1) q = 1;
      if (q > n) q = n;
      k_table[e * CNT_W +: CNT_W] = CNT_W'(q);
    end
  endfunction
  localparam logic [NE*CNT_W-1:0] KTAB = k_table();

  // Stages 3, 4: the column word, masks, the row's scale and k
  logic [ROWS*POW_W-1:0] cw3_q, cw4_q;
  logic [ROWS-1:0]       mo3_q, mi3_q, mo4_q, mi4_q;
  logic [E_W-1:0]        e3_q;
  logic [SCALE_W-1:0]    inv4_q;
  logic [CNT_W-1:0]      k_q [8:4];
  always_ff @(posedge clk) begin
    cw3_q  <= cw2;
    mo3_q  <= mo2;
    mi3_q  <= mi2;
    e3_q   <= e2;
    cw4_q  <= cw3_q;
    mo4_q  <= mo3_q;
    mi4_q  <= mi3_q;
    inv4_q <= cfg_scale[e3_q * SCALE_W +: SCALE_W];
    k_q[4] <= KTAB[e3_q * CNT_W +: CNT_W];
    for (int k = 5; k <= 8; k++) k_q[k] <= k_q[k-1];
  end

  // Full column words of the previous 2*PD columns (index 0 = newest)
  logic [2*PD-1:0][ROWS*POW_W-1:0] sr_w;
  always_ff @(posedge clk)
    if (ev4) begin
      sr_w[0] <= cw4_q;
      for (int k = 1; k < 2 * PD; k++) sr_w[k] <= sr_w[k-1];
    end

  // Threshold chain on the shifts: t[0] partial products of the arriving CUT-row cell and
  // the scale, t[1] T, then delay; t[PD-1] holds the CUT at shift-register position PD-1
  localparam int CH = 17;
  localparam int NA = (POW_W + CH - 1) / CH;
  localparam int NB = (SCALE_W + CH - 1) / CH;
  localparam int P_W = POW_W + SCALE_W;
  logic [NA*CH-1:0] a4;
  logic [NB*CH-1:0] b4;
  logic [2*CH-1:0]  pp_q [NA][NB];
  logic             nz_q;                    // CUT * inv != 0
  logic [PD-1:1][POW_W-1:0] thr_q;           // T (low bits)
  logic [PD-1:1]            big_q, none_q;   // T >= 2^POW_W; no cell passes
  assign a4 = (NA * CH)'(vcut4);
  assign b4 = (NB * CH)'(inv4_q);
  always_ff @(posedge clk)
    if (ev4) begin
      logic [P_W-1:0] acc;
      for (int i = 0; i < NA; i++)
        for (int j = 0; j < NB; j++)
          pp_q[i][j] <= (2 * CH)'(a4[i * CH +: CH]) * (2 * CH)'(b4[j * CH +: CH]);
      nz_q <= (vcut4 != '0) && (inv4_q != '0);
      acc = '1;                              // -1: T = floor((P - 1) / 2^SCALE_FRAC)
      for (int i = 0; i < NA; i++)
        for (int j = 0; j < NB; j++)
          acc = acc + (P_W'(pp_q[i][j]) << ((i + j) * CH));
      thr_q[1]  <= acc[SCALE_FRAC +: POW_W];
      big_q[1]  <= (acc[P_W-1:SCALE_FRAC+POW_W] != '0);
      none_q[1] <= !nz_q;
      for (int k = 2; k < PD; k++) begin
        thr_q[k]  <= thr_q[k-1];
        big_q[k]  <= big_q[k-1];
        none_q[k] <= none_q[k-1];
      end
    end

  // Stage 5: comparator bits of the training cells. Column j of the window: j = 0 the
  // arriving column (Doppler offset +PD), j = k+1 shift-register position k (offset
  // PD-1-k); guard columns |offset| <= GUARD_D drop the guard rows.
  logic [NC-1:0] hit5_q;
  always_ff @(posedge clk)
    for (int j = 0; j < NCOL; j++)
      for (int s = 0; s < ROWS; s++) begin
        logic [POW_W-1:0] x;
        logic             train;
        x = (j == 0) ? cw4_q[s * POW_W +: POW_W] : sr_w[(j == 0) ? 0 : j - 1][s * POW_W +: POW_W];
        train = mo4_q[s] && !(mi4_q[s] && (PD - j <= GUARD_D) && (j - PD <= GUARD_D));
        hit5_q[j * ROWS + s] <= train && !none_q[PD-1] && (big_q[PD-1] || x <= thr_q[PD-1]);
      end

  // Stages 6-8: popcount as balanced adder trees: groups of 8 bits, groups of 8 counts
  // (3 levels each), the total of the group counts (3 levels up to 512 comparators)
  localparam int G2P = (G2 < 2) ? 2 : (1 << $clog2(G2));   // stage-8 tree width
  logic [3:0]     c6_q [G1];
  logic [6:0]     c7_q [G2];
  logic [CNT_W:0] c8_q;
  always_ff @(posedge clk) begin
    logic [3:0]     t6 [8];
    logic [6:0]     t7 [8];
    logic [CNT_W:0] t8 [G2P];
    for (int g = 0; g < G1; g++) begin
      for (int b = 0; b < 8; b++) t6[b] = (g * 8 + b < NC) ? 4'(hit5_q[(g * 8 + b) % NC]) : '0;
      for (int w = 4; w >= 1; w = w / 2)
        for (int b = 0; b < w; b++) t6[b] = t6[2 * b] + t6[2 * b + 1];
      c6_q[g] <= t6[0];
    end
    for (int g = 0; g < G2; g++) begin
      for (int b = 0; b < 8; b++) t7[b] = (g * 8 + b < G1) ? 7'(c6_q[(g * 8 + b) % G1]) : '0;
      for (int w = 4; w >= 1; w = w / 2)
        for (int b = 0; b < w; b++) t7[b] = t7[2 * b] + t7[2 * b + 1];
      c7_q[g] <= t7[0];
    end
    for (int b = 0; b < G2P; b++) t8[b] = (b < G2) ? (CNT_W + 1)'(c7_q[b % G2]) : '0;
    for (int w = G2P / 2; w >= 1; w = w / 2)
      for (int b = 0; b < w; b++) t8[b] = t8[2 * b] + t8[2 * b + 1];
    c8_q <= t8[0];
  end

  // Stage 9: at least k cells
  always_ff @(posedge clk) os9 <= (c8_q >= (CNT_W + 1)'(k_q[8]));

endmodule

`default_nettype wire
