// SPDX-License-Identifier: Apache-2.0
// cfar_2d's training sums and threshold test (stages 4..10 of its pipeline, docs/detect.md):
// the column delay lines (cfar_ring.sv), the running window sums over them, the training
// sum S of the kind
// chosen at run time (CA: all training cells; GO / SO: the greater / smaller of the two
// Doppler halves, offsets < 0 and > 0; OS uses the CA sum as its noise estimate), the
// product S * scale and the test CUT * 2^SCALE_FRAC > S * scale.
`default_nettype none

module cfar_sums #(
  parameter int PD = 10,          // GUARD_D + TRAIN_D
  parameter int GUARD_D = 2,
  parameter int POW_W = 34,
  parameter int SUM_W = 43,
  parameter int VS_W = 38,        // vertical sums (cfar_vsum.sv): POW_W + clog2(2*PR+1)
  parameter int S_W = 9,          // column step counter width
  parameter int SCALE_W = 32,
  parameter int SCALE_FRAC = 20,
  // 1: only the CA sum is ever used (kind constant CA or OS): two running sums, as before
  // the run-time kind; 0: the GO/SO halves too (four running sums)
  parameter bit CA_ONLY = 1'b0
) (
  input  wire logic                          clk,
  // stage 4: a tested row's column arrives (the shift register shifts), column step 0 of
  // the pass (the running sums restart), the step counter one clock earlier (stage 3)
  input  wire logic                          ev4,
  input  wire logic                          first4,
  input  wire logic [S_W-1:0]                s3,
  // stage 4: the arriving column's vertical sums over the window rows (o) and guard rows
  // (i)
  input  wire logic [VS_W-1:0]               vo4,
  input  wire logic [VS_W-1:0]               vi4,
  // quasi-static kind: 0 CA, 1 GO, 2 SO, 3 OS (S = the CA sum)
  input  wire logic [1:0]                    kind,
  // stage 5: the cell under test and its row's threshold scale
  input  wire logic [POW_W-1:0]              cut5,
  input  wire logic [SCALE_W-1:0]            scale5,
  // stage 5: training sum S of the kind (from stage-5 registers); stage 10:
  // CUT * 2^SCALE_FRAC > S * scale
  output logic      [SUM_W-1:0]              sum5,
  output logic                               over10
);

  localparam int PROD_W = SUM_W + SCALE_W;

  // Running window sums: wsum[w] = sum of sr_x[A..B] before the shift (x = o or i), kept
  // by adding the entry that enters position A and subtracting the one leaving B at each
  // shift; an entry counts only once it belongs to this pass (at column step s, position k
  // holds the pass's column s-1-k), so the sum restarts at step 0. w0/w1: left half o/i
  // (positions PD..2PD-1), w2/w3: right half o/i (the arriving column and 0..PD-2); the
  // CUT's column (position PD-1) is added for CA. CA_ONLY: w0 = o over positions 0..2PD-1,
  // w1 = i over the guard columns.
  // (results assigned to the function name, no `return`: Yosys reads the file as written)
  function automatic int win_a(input int w);
    if (CA_ONLY) win_a = (w == 0) ? 0 : PD - 1 - GUARD_D;
    else         win_a = (w < 2) ? PD : ((w == 2) ? 0 : PD - 1 - GUARD_D);
  endfunction
  function automatic int win_b(input int w);
    if (CA_ONLY) win_b = (w == 0) ? 2 * PD - 1 : PD - 1 + GUARD_D;
    else         win_b = (w == 0) ? 2 * PD - 1 : ((w == 1) ? PD - 1 + GUARD_D : PD - 2);
  endfunction
  localparam int NW = CA_ONLY ? 2 : 4;

  // The previous 2*PD columns' sums (index 0 = newest), a shift register on ev4 read only
  // at the positions the windows use (entering, leaving, the CUT's column): rings in
  // distributed RAM (cfar_ring.sv), VS_W bits wide (a column sum's width)
  function automatic logic [2*PD-1:0] taps(input bit o);
    taps = '0;
    for (int w = 0; w < NW; w++)
      if ((w % 2 == 0) == o && win_b(w) >= win_a(w)) begin
        if (win_a(w) > 0) taps[win_a(w) - 1] = 1'b1;
        taps[win_b(w)] = 1'b1;
      end
    if (!CA_ONLY) taps[PD-1] = 1'b1;
  endfunction
  logic [2*PD-1:0][VS_W-1:0] sr_o, sr_i;
  cfar_ring #(.W(VS_W), .N(2 * PD), .USED(taps(1'b1))) u_ring_o (
    .clk(clk), .en(ev4), .d(vo4), .q(sr_o));
  cfar_ring #(.W(VS_W), .N(2 * PD), .USED(taps(1'b0))) u_ring_i (
    .clk(clk), .en(ev4), .d(vi4), .q(sr_i));
  logic [SUM_W-1:0] wsum [4];
  for (genvar w = 0; w < 4; w++) begin : g_win
    localparam int A = win_a(w);
    localparam int B = win_b(w);
    localparam bit IS_O = (w % 2 == 0);
    if (w >= NW || B < A) begin : g_empty
      assign wsum[w] = '0;
    end else begin : g_run
      logic [SUM_W-1:0] w_q;
      logic [VS_W-1:0]  enter, leave;
      logic             en_q, lv_q;
      if (A == 0) begin : g_arriving
        assign enter = IS_O ? vo4 : vi4;
        assign en_q  = 1'b1;
      end else begin : g_shifted
        assign enter = IS_O ? sr_o[A-1] : sr_i[A-1];
        always_ff @(posedge clk) en_q <= (s3 >= S_W'(A));
      end
      assign leave   = IS_O ? sr_o[B] : sr_i[B];
      assign wsum[w] = first4 ? '0 : w_q;
      always_ff @(posedge clk) begin
        lv_q <= (s3 >= S_W'(B + 1));
        if (ev4) w_q <= wsum[w] + SUM_W'(en_q ? enter : '0) - SUM_W'(lv_q ? leave : '0);
      end
    end
  end

  // Stage 5: the two halves and the CUT's column (CA_ONLY: the CA sum); s5 the training sum
  // of the kind (cfar_2d's early output FIFO takes it at stage 5)
  logic [SUM_W-1:0] sa5_q, s5;
  if (CA_ONLY) begin : g_ca_sum
    always_ff @(posedge clk) sa5_q <= wsum[0] + SUM_W'(vo4) - wsum[1];
    assign s5 = sa5_q;
    logic unused_kind;            // the kind is CA or OS (the CA sum) by construction
    assign unused_kind = ^kind;
  end else begin : g_half_sums
    logic [SUM_W-1:0] sb5_q;
    logic [VS_W-1:0]  sc5_q;     // the CUT's column: window rows minus guard rows, >= 0
    always_ff @(posedge clk) begin
      sa5_q <= wsum[0] - wsum[1];
      sb5_q <= wsum[2] + SUM_W'(vo4) - wsum[3];
      sc5_q <= sr_o[PD-1] - sr_i[PD-1];
    end
    always_comb
      unique case (kind)
        2'd1:    s5 = (sa5_q > sb5_q) ? sa5_q : sb5_q;
        2'd2:    s5 = (sa5_q < sb5_q) ? sa5_q : sb5_q;
        default: s5 = sa5_q + sb5_q + SUM_W'(sc5_q);
      endcase
  end

  assign sum5 = s5;

  // Stage 6: training sum S of the kind, the row's threshold scale (multiplier inputs)
  logic [SUM_W-1:0]   sum6_q;
  logic [SCALE_W-1:0] scale6_q;
  logic [POW_W-1:0]   cut_q [9:6];
  always_ff @(posedge clk) begin
    sum6_q   <= s5;
    scale6_q <= scale5;
    cut_q[6] <= cut5;
    for (int k = 7; k <= 9; k++) cut_q[k] <= cut_q[k-1];
  end

  // Stages 7-9: S * scale from CH-bit chunks, S = sum_i S_i 2^(CH i), scale likewise:
  // products registered (7), then per scale chunk j the even-i and odd-i products, each a
  // concatenation (a product is 2 CH bits wide), added (8), then the chunk sums (9)
  localparam int CH = 17;
  localparam int NA = (SUM_W + CH - 1) / CH;
  localparam int NB = (SCALE_W + CH - 1) / CH;
  logic [NA*CH-1:0]   a6;
  logic [NB*CH-1:0]   b6;
  logic [2*CH-1:0]    pp7_q [NA][NB];
  logic [(NA+1)*CH:0] col8_q [NB];
  logic [PROD_W-1:SCALE_FRAC] prod9_q;   // the product's bits that the decision uses
  assign a6 = (NA * CH)'(sum6_q);
  assign b6 = (NB * CH)'(scale6_q);
  always_ff @(posedge clk) begin
    logic [(NA+1)*CH-1:0] ev, od;
    logic [PROD_W-1:0]    acc;
    for (int i = 0; i < NA; i++)
      for (int j = 0; j < NB; j++)
        pp7_q[i][j] <= (2 * CH)'(a6[i * CH +: CH]) * (2 * CH)'(b6[j * CH +: CH]);
    for (int j = 0; j < NB; j++) begin
      ev = '0;
      od = '0;
      for (int i = 0; i < NA; i++)
        if (i % 2 == 0) ev[i * CH +: 2 * CH] = pp7_q[i][j];
        else            od[i * CH +: 2 * CH] = pp7_q[i][j];
      col8_q[j] <= ((NA + 1) * CH + 1)'(ev) + ((NA + 1) * CH + 1)'(od);
    end
    acc = '0;
    for (int j = 0; j < NB; j++) acc = acc + (PROD_W'(col8_q[j]) << (j * CH));
    prod9_q <= acc[PROD_W-1:SCALE_FRAC];
  end

  // Stage 10: CUT * 2^SCALE_FRAC > P  <=>  CUT > floor(P / 2^SCALE_FRAC)
  localparam int PH_W = PROD_W - SCALE_FRAC;
  logic [PH_W-1:0] prod_hi;
  assign prod_hi = prod9_q;
  always_ff @(posedge clk)
    over10 <= (prod_hi[PH_W-1:POW_W] == '0) && (cut_q[9] > prod_hi[POW_W-1:0]);

endmodule

`default_nettype wire
