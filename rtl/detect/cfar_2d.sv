// SPDX-License-Identifier: Apache-2.0
// 2-D CFAR on the integrated power map, circular in Doppler: cell averaging (CA),
// greatest-of (GO), smallest-of (SO) or, when built, ordered statistic (OS), chosen at run
// time (cfg_kind), with an optional 3x3 local-maximum test (cfg_local_max). Training window
// cut at the range ends with a per-edge-row threshold scale, the top BLANK_TOP range bins
// blanked (never tested, never used for training). Streams the map in (for r, for d) and
// sends every cell out with its training sum and cell count, the detection flag and the
// powers of its four neighbours (what the host's peak interpolation needs).
//
// Architecture (docs/detect.md): a column store of N_DOPPLER words, each holding the cells
// of the last ROWS = 2*PR+2 range rows of that Doppler column. Pass p writes input row p
// (read-modify-write, one cell per clock) and tests row q = p-PR-1, whose window rows
// q-PR..q+PR are complete: the vertical sums of every column (cfar_vsum.sv) stream through
// a shift register of 2*PD+1 columns; the circular wrap is closed by replaying columns
// 0..2*PD-1 after column N_DOPPLER-1. After the last input row, PR+1 passes without input
// test the remaining rows. Output order per row: d = PD..N_DOPPLER-1, 0..PD-1 ({r, d} in
// tuser). Detection: CUT * 2^SCALE_FRAC > S * cfg_scale[e] (exact integers; cfar_sums.sv),
// S the training sum of the kind, e the edge index of the row (0..PR-1: PR-e rows cut
// below, PR: interior, PR+1..2*PR: e-PR rows cut above); OS (cfar_os.sv): at least k(e)
// training cells X with X * 2^SCALE_FRAC < CUT * cfg_scale[e] (the inverse scale); the
// scales from model/cfar_2d.py. Local maximum (cfar_peak.sv): no 8-neighbour greater.
`default_nettype none

module cfar_2d #(
  // Range bins per frame, power of two, 4..4096.
  parameter int N_RANGE = 64,
  // Doppler bins per row, power of two, 4..4096.
  parameter int N_DOPPLER = 256,
  // Bits of the input power (nci POW_W), 8..62.
  parameter int POW_W = 34,
  // Guard cells per side along range / Doppler, 0..15.
  parameter int GUARD_R = 2,
  parameter int GUARD_D = 2,
  // Training cells per side along range / Doppler, 1..15.
  parameter int TRAIN_R = 4,
  parameter int TRAIN_D = 8,
  // Default kind (what cfg_kind is tied to when it is not a register; a cfg_kind code of a
  // kind not built selects KIND): 0: CA (all training cells), 1: GO (greater of the
  // left/right Doppler halves), 2: SO (smaller of the halves), 3: OS (k-th smallest
  // training cell; builds the OS test). Halves: Doppler offsets < 0 and > 0 (the CUT's own
  // column is not in either half).
  parameter int KIND = 0,
  // Build the OS test (cfar_os.sv: the window's column words and one comparator per
  // training cell): 1 when KIND = 3, else 0 unless set. OS rank k = OS_RANK / 1000 of the
  // training cells (rounded half to even, at least 1).
  parameter bit OS_BUILD = (KIND == 3),
  parameter int OS_RANK = 750,
  // Kinds CA, GO, SO that cfg_kind may select (bit k: kind k; KIND is always built): 3'b111
  // (default) all three; with KIND's bit alone and no OS_BUILD the one kind, the smaller
  // build (CA alone: two running window sums instead of four, no kind multiplexers).
  parameter logic [2:0] RUN_KINDS = 3'b111,
  // Build the 3x3 local-maximum test (0: cfg_local_max is ignored, the test off).
  parameter bit LOCAL_MAX_BUILD = 1'b1,
  // Top range bins blanked (the negative beat frequencies of a complex-IF range FFT):
  // rows N_RANGE-BLANK_TOP..N_RANGE-1 are not tested and not used as training cells,
  // 0..N_RANGE-2*(GUARD_R+TRAIN_R)-1.
  parameter int BLANK_TOP = 0,
  // Range rows that may report a detection: REPORT_LO <= r < REPORT_HI (model.config
  // RadarConfig.detection_bins, the host's rule). Rows outside are still training cells
  // (unlike BLANK_TOP) but their detect bit is 0 and they are not counted.
  parameter int REPORT_LO = 0,
  parameter int REPORT_HI = N_RANGE,
  // Threshold scale: unsigned fixed point, SCALE_W bits with SCALE_FRAC fraction bits.
  parameter int SCALE_W = 32,
  parameter int SCALE_FRAC = 20,
  // Derived, do not override: input tdata width, training sum and count widths.
  parameter int IN_W = ((POW_W + 7) / 8) * 8,
  parameter int CNT_W = $clog2((2 * (GUARD_R + TRAIN_R) + 1) * (2 * (GUARD_D + TRAIN_D) + 1)),
  parameter int SUM_W = POW_W + CNT_W,
  parameter int OUT_W = ((5 * POW_W + SUM_W + CNT_W + 1 + 7) / 8) * 8
) (
  input  wire logic                     clk,
  input  wire logic                     rst,
  // Threshold scale per edge index e = 0..2*PR (quasi-static: change only while idle)
  input  wire logic [(2*(GUARD_R+TRAIN_R)+1)*SCALE_W-1:0] cfg_scale,
  // Kind, 0 CA, 1 GO, 2 SO, 3 OS (quasi-static); the 3x3 local-maximum test on (quasi-static)
  input  wire logic [1:0]               cfg_kind,
  input  wire logic                     cfg_local_max,
  // Power map, order (r, d), TLAST on Doppler bin N_DOPPLER-1 (checked only)
  input  wire logic [IN_W-1:0]          s_axis_tdata,
  input  wire logic                     s_axis_tvalid,
  output logic                          s_axis_tready,
  input  wire logic                     s_axis_tlast,
  // Tested cells: tdata = {pow(r, d+1), pow(r, d-1), pow(r+1, d), pow(r-1, d), detect,
  // count, sum, power} (zero-extended to OUT_W; Doppler circular, a range neighbour
  // outside 0..N_RANGE-1 is 0), tuser = {r, d}, TLAST on the last cell of every row
  output logic      [OUT_W-1:0]         m_axis_tdata,
  output logic                          m_axis_tvalid,
  input  wire logic                     m_axis_tready,
  output logic                          m_axis_tlast,
  output logic      [$clog2(N_RANGE)+$clog2(N_DOPPLER)-1:0] m_axis_tuser,
  // Status (cleared only by rst)
  output logic                          status_framing_error,  // sticky: TLAST misplaced
  output logic      [31:0]              frame_count,           // frames completely tested
  output logic      [31:0]              detection_count        // detections (saturating)
);

  localparam int PR    = GUARD_R + TRAIN_R;
  localparam int PD    = GUARD_D + TRAIN_D;
  localparam int NE    = 2 * PR + 1;                 // edge indices / window rows
  localparam int ROWS  = 2 * PR + 2;                 // rows held per column
  localparam int SLOT_W = $clog2(ROWS);
  localparam int BR    = $clog2(N_RANGE);
  localparam int BD    = $clog2(N_DOPPLER);
  localparam int NPASS = N_RANGE + PR + 1;           // passes per frame
  localparam int P_W   = $clog2(NPASS + 1);
  localparam int S_W   = $clog2(N_DOPPLER + 2 * PD + 1);
  localparam int N_EFF = N_RANGE - BLANK_TOP;        // rows that exist for the CFAR
  // kinds built (bit k: kind k) and whether cfg_kind has a choice
  localparam logic [3:0] BUILT = {OS_BUILD, RUN_KINDS} | (4'b0001 << KIND);
  localparam bit ONE_KIND = (BUILT == (4'b0001 << KIND));
  localparam int CW_W  = ROWS * POW_W;               // column word
  localparam int VS_W  = POW_W + $clog2(NE);         // a column's vertical sum (NE odd)

  // Parameter checks: stop elaboration on illegal values.
  if (N_RANGE < 4 || N_RANGE > 4096 || (1 << BR) != N_RANGE) begin : g_bad_n_range
    $fatal(1, "%m: N_RANGE=%0d must be a power of two in 4..4096", N_RANGE);
  end
  if (N_DOPPLER < 4 || N_DOPPLER > 4096 || (1 << BD) != N_DOPPLER) begin : g_bad_n_doppler
    $fatal(1, "%m: N_DOPPLER=%0d must be a power of two in 4..4096",
           N_DOPPLER);
  end
  if (POW_W < 8 || POW_W > 62) begin : g_bad_pow_w
    $fatal(1, "%m: POW_W=%0d not in 8..62", POW_W);
  end
  if (GUARD_R < 0 || GUARD_R > 15 || GUARD_D < 0 || GUARD_D > 15) begin : g_bad_guard
    $fatal(1, "%m: GUARD_R=%0d/GUARD_D=%0d not in 0..15", GUARD_R, GUARD_D);
  end
  if (TRAIN_R < 1 || TRAIN_R > 15 || TRAIN_D < 1 || TRAIN_D > 15) begin : g_bad_train
    $fatal(1, "%m: TRAIN_R=%0d/TRAIN_D=%0d not in 1..15", TRAIN_R, TRAIN_D);
  end
  if (2 * PD + 1 > N_DOPPLER) begin : g_bad_train_d
    $fatal(1, "%m: TRAIN_D/GUARD_D: window %0d wider than N_DOPPLER=%0d",
           2 * PD + 1, N_DOPPLER);
  end
  if (KIND < 0 || KIND > 3 || (KIND == 3 && !OS_BUILD)) begin : g_bad_kind
    $fatal(1, "%m: KIND=%0d not 0 (CA), 1 (GO), 2 (SO) or 3 (OS, OS_BUILD = 1)", KIND);
  end
  if (BLANK_TOP < 0 || N_EFF < 2 * PR + 1) begin : g_bad_blank_top
    $fatal(1, "%m: BLANK_TOP=%0d leaves %0d rows, need >= %0d",
           BLANK_TOP, N_EFF, 2 * PR + 1);
  end
  if (REPORT_LO < 0 || REPORT_HI > N_RANGE || REPORT_LO >= REPORT_HI) begin : g_bad_report
    $fatal(1, "%m: REPORT_LO=%0d/REPORT_HI=%0d: need 0 <= LO < HI <= N_RANGE=%0d",
           REPORT_LO, REPORT_HI, N_RANGE);
  end
  if (SCALE_W < 2 || SCALE_W > 48 || SCALE_FRAC < 0 || SCALE_FRAC >= SCALE_W)
  begin : g_bad_scale_w
    $fatal(1, "%m: SCALE_W=%0d/SCALE_FRAC=%0d: need 2..48 and 0 <= FRAC < W",
           SCALE_W, SCALE_FRAC);
  end
  if (CW_W > 4096) begin : g_bad_column_word
    $fatal(1, "%m: (2*PR+2)*POW_W=%0d bits per column above 4096", CW_W);
  end
  if (IN_W < POW_W || CNT_W < 1 || SUM_W != POW_W + CNT_W ||
      OUT_W < 5 * POW_W + SUM_W + CNT_W + 1)
  begin : g_bad_derived
    $fatal(1, "%m: IN_W/CNT_W/SUM_W/OUT_W are derived, do not override");
  end

  // ---------------------------------------------------------------------------------------
  // Pass and column sequencing
  logic [P_W-1:0]    p_q;        // pass within the frame, 0..NPASS-1
  logic [S_W-1:0]    s_q;        // column step within the pass
  logic [SLOT_W-1:0] slot_q;     // p mod ROWS: slot written by this pass
  logic              framing_q;
  logic [31:0]       frame_cnt_q, det_cnt_q;
  logic              can_issue, in_phase, testing, step, pass_end, need_in;
  logic [S_W-1:0]    pass_len;
  logic [BD-1:0]     col;

  assign testing  = (p_q >= P_W'(PR + 1));
  assign pass_len = testing ? S_W'(N_DOPPLER + 2 * PD) : S_W'(N_DOPPLER);
  assign need_in  = (p_q < P_W'(N_RANGE));
  assign in_phase = need_in && (s_q < S_W'(N_DOPPLER));
  assign step     = can_issue && (!in_phase || s_axis_tvalid);
  assign s_axis_tready = can_issue && in_phase;
  assign pass_end = (s_q == pass_len - 1'b1);
  assign col      = (s_q < S_W'(N_DOPPLER)) ? BD'(s_q) : BD'(s_q - S_W'(N_DOPPLER));

  // ---------------------------------------------------------------------------------------
  // Pipeline: one column step per clock, no stall inside (a step is taken only when the
  // output FIFOs have room for every cell in flight). Stage k = k clocks after the step:
  //  1 column store read (the RAM's own register), the row geometry; 2 read data registered
  //  again, written back with the input cell, slot masks; 3-4 vertical sums (cfar_vsum.sv):
  //  the column arrives, shifts into the column shift register; 5 window sums; the cell,
  //  its neighbours, count, training sum S of the kind, {r, d}, TLAST -> early output FIFO;
  //  6 S registered for the multiplier, local maximum (cfar_peak.sv); 7-9 S * scale
  //  (17 x 17-bit partial products, one DSP48E2 each; cfar_sums.sv); OS (cfar_os.sv)
  //  comparators 5, popcount 6-8, count >= k 9; 10 the decision of the kind -> late output
  //  FIFO
  localparam int LAT_E = 5;     // step -> early FIFO entry
  localparam int LAT_L = 10;    // step -> late FIFO entry (the output's valid)

  // ---------------------------------------------------------------------------------------
  // Column store: word d = cells of column d of the last ROWS rows, slot = row mod ROWS
  logic [CW_W-1:0]   cw_rd, cw2_q, cw_wr;
  logic              st_wr1_q, st_wr2_q;
  logic [BD-1:0]     st_col1_q, st_col2_q;
  logic [SLOT_W-1:0] st_slot1_q;
  logic [POW_W-1:0]  st_x1_q, st_x2_q;
  logic [ROWS-1:0]   wsel2_q;   // slot written back (one-hot)

  buf_sdp_ram #(.WIDTH(CW_W), .DEPTH(N_DOPPLER)) u_store (
    .clk     (clk),
    .wr_en   (st_wr2_q),
    .wr_addr (st_col2_q),
    .wr_data (cw_wr),
    .rd_en   (step),
    .rd_addr (col),
    .rd_data (cw_rd)
  );

  // A column is read again N_DOPPLER >= 4 steps after its write-back (2 clocks after its
  // read): no read-after-write hazard.
  always_ff @(posedge clk) cw2_q <= cw_rd;

  always_comb begin
    cw_wr = cw2_q;
    for (int s = 0; s < ROWS; s++)
      if (wsel2_q[s]) cw_wr[s * POW_W +: POW_W] = st_x2_q;
  end

  // ---------------------------------------------------------------------------------------
  // Row geometry of pass p (tested row q = p - PR - 1): which window rows exist, the edge
  // index, whether the row may detect and has range neighbours. It changes only between
  // passes, so the next pass's geometry is computed ahead in three register stages (a pass
  // lasts at least N_DOPPLER >= 4 clocks) and loaded at the pass end.
  localparam int E_W   = $clog2(NE);
  localparam int NR_W  = $clog2(NE + 1);
  localparam int GEO_W = 3 + BR + E_W + NE;   // {cut_ok, rm_ok, rp_ok, r, e, rowv}
  // (results assigned to the function name, no `return`: Yosys reads the file as written)
  function automatic logic [GEO_W-1:0] geo(input int p);
    int q, row, lo, hi;
    logic [NE-1:0] rv;
    q = p - PR - 1;
    for (int k = 0; k < NE; k++) begin
      row   = q - PR + k;
      rv[k] = (row >= 0) && (row < N_EFF);     // window row k (row q-PR+k) exists
    end
    lo = (q < PR) ? PR - q : 0;                          // rows cut below
    hi = (q + PR > N_EFF - 1) ? q + PR - (N_EFF - 1) : 0;  // rows cut above
    if (hi > PR) hi = PR;                                  // blanked rows (not tested)
    geo = {(q < N_EFF) && (q >= REPORT_LO) && (q < REPORT_HI),   // may detect
           q >= 1,                                               // row q-1 exists
           q + 1 < N_RANGE,                                      // row q+1 exists
           BR'(q), E_W'((lo > 0) ? PR - lo : PR + hi), rv};
  endfunction
  // existing rows: whole window (guard = 0) / guard band (guard = 1), an adder tree
  function automatic logic [NR_W-1:0] n_rows(input logic [NE-1:0] rv, input bit guard);
    logic [NR_W-1:0] t [64];
    for (int k = 0; k < 64; k++)
      t[k] = (k < NE && rv[k % NE] && (!guard || (k >= PR - GUARD_R && k <= PR + GUARD_R)))
             ? NR_W'(1) : '0;
    for (int w = 32; w >= 1; w = w / 2)
      for (int k = 0; k < w; k++) t[k] = t[2 * k] + t[2 * k + 1];
    n_rows = t[0];
  endfunction

  localparam logic [GEO_W-1:0] GEO0 = geo(0);
  logic [P_W-1:0]   pn1_q;               // next pass
  logic [GEO_W-1:0] geo_n2_q, geo_q;     // its geometry; the current pass's
  logic [NR_W-1:0]  nout_n3_q, nin_n3_q, nout_q, nin_q;
  always_ff @(posedge clk) begin
    pn1_q     <= (p_q == P_W'(NPASS - 1)) ? '0 : p_q + 1'b1;
    geo_n2_q  <= geo(int'(pn1_q));
    nout_n3_q <= n_rows(geo_n2_q[NE-1:0], 1'b0);
    nin_n3_q  <= n_rows(geo_n2_q[NE-1:0], 1'b1);
    if (rst) begin
      geo_q  <= GEO0;
      nout_q <= n_rows(GEO0[NE-1:0], 1'b0);
      nin_q  <= n_rows(GEO0[NE-1:0], 1'b1);
    end else if (step && pass_end) begin
      geo_q  <= geo_n2_q;
      nout_q <= nout_n3_q;
      nin_q  <= nin_n3_q;
    end
  end

  // Per-cell control, carried down the pipeline (index = stage)
  logic [4:1]        v_q;        // a step's data is in stage k (reset)
  logic [4:1]        test_q, out_q, last_q, cut_ok_q, rm_ok_q, rp_ok_q;
  logic [BR-1:0]     r_q [5:1];
  logic [BD-1:0]     d_q [5:4];  // centre column (mod N_DOPPLER), from s_q3
  logic [E_W-1:0]    e_q [5:1];
  logic [S_W-1:0]    s_q1, s_q2, s_q3;
  logic [NE-1:0]     rowv1_q;
  logic [NR_W-1:0]   n_out1_q, n_in1_q;
  logic [CNT_W-1:0]  cnt_q [5:2];
  logic [1:0]        kind_q;     // cfg_kind, a kind that is not built replaced by KIND
  logic              lm_q;
  if (ONE_KIND) begin : g_one_kind
    assign kind_q = 2'(KIND);
  end else begin : g_run_kind
    always_ff @(posedge clk) kind_q <= BUILT[cfg_kind] ? cfg_kind : 2'(KIND);
  end
  if (LOCAL_MAX_BUILD) begin : g_local_max
    always_ff @(posedge clk) lm_q <= cfg_local_max;
  end else begin : g_no_local_max
    assign lm_q = 1'b0;
  end

  always_ff @(posedge clk) begin
    st_col1_q   <= col;
    st_slot1_q  <= slot_q;
    st_x1_q     <= s_axis_tdata[POW_W-1:0];
    st_col2_q   <= st_col1_q;
    st_x2_q     <= st_x1_q;
    test_q[1]   <= testing;
    out_q[1]    <= testing && (s_q >= S_W'(2 * PD));
    last_q[1]   <= pass_end;
    {cut_ok_q[1], rm_ok_q[1], rp_ok_q[1], r_q[1], e_q[1], rowv1_q} <= geo_q;
    s_q1        <= s_q;
    n_out1_q    <= nout_q;
    n_in1_q     <= nin_q;
    for (int k = 2; k <= 4; k++) begin
      test_q[k]   <= test_q[k-1];
      out_q[k]    <= out_q[k-1];
      last_q[k]   <= last_q[k-1];
      cut_ok_q[k] <= cut_ok_q[k-1];
      rm_ok_q[k]  <= rm_ok_q[k-1];
      rp_ok_q[k]  <= rp_ok_q[k-1];
    end
    for (int k = 2; k <= 5; k++) begin
      r_q[k] <= r_q[k-1];
      e_q[k] <= e_q[k-1];
    end
    s_q2   <= s_q1;
    s_q3   <= s_q2;
    d_q[4] <= BD'(s_q3 - S_W'(PD));
    d_q[5] <= d_q[4];
    if (kind_q == 2'd1 || kind_q == 2'd2)
      cnt_q[2] <= CNT_W'(n_out1_q * PD - n_in1_q * GUARD_D);
    else
      cnt_q[2] <= CNT_W'(n_out1_q * (2 * PD + 1) - n_in1_q * (2 * GUARD_D + 1));
    for (int k = 3; k <= 5; k++) cnt_q[k] <= cnt_q[k-1];
  end

  // Stage 1: write-back slot; stages 2..4: slot masks, vertical sums (cfar_vsum.sv)
  always_ff @(posedge clk)
    for (int s = 0; s < ROWS; s++) wsel2_q[s] <= (st_slot1_q == SLOT_W'(s));
  logic [ROWS-1:0]  mo2_q, mi2_q;
  logic [VS_W-1:0]  vo4_q, vi4_q;
  logic [POW_W-1:0] vcut4_q, rm4_q, rp4_q;
  logic             first4_q;    // column step 0 of the pass (the running sums restart)
  cfar_vsum #(.ROWS(ROWS), .NE(NE), .PR(PR), .GUARD_R(GUARD_R), .POW_W(POW_W)) u_vsum (
    .clk(clk), .slot1(st_slot1_q), .rowv1(rowv1_q), .cw2(cw2_q), .mo2(mo2_q), .mi2(mi2_q),
    .vo4(vo4_q), .vi4(vi4_q), .vcut4(vcut4_q), .rm4(rm4_q), .rp4(rp4_q)
  );
  always_ff @(posedge clk) first4_q <= (s_q3 == '0);

  logic             ev4;         // a tested row's column arrives (the delay lines shift)
  assign ev4 = v_q[4] && test_q[4];

  // Stages 4..6: the cell, its neighbours, the local-maximum test (cfar_peak.sv)
  logic [POW_W-1:0] cut5, nb_rm5, nb_rp5, nb_dm5, nb_dp5;
  logic             peak6;
  cfar_peak #(.PD(PD), .POW_W(POW_W)) u_peak (
    .clk(clk), .ev4(ev4), .vcut4(vcut4_q), .rm4(rm4_q), .rp4(rp4_q), .rm_ok4(rm_ok_q[4]),
    .rp_ok4(rp_ok_q[4]), .cut5(cut5), .nb_rm5(nb_rm5), .nb_rp5(nb_rp5),
    .nb_dm5(nb_dm5), .nb_dp5(nb_dp5), .peak6(peak6)
  );

  logic last5_q, ok5_q;
  logic peak_q [10:7];
  logic ok_q [10:6];
  always_ff @(posedge clk) begin
    last5_q   <= last_q[4];
    ok5_q     <= cut_ok_q[4];
    ok_q[6]   <= ok5_q;
    peak_q[7] <= peak6;
    for (int k = 7; k <= 10; k++) ok_q[k] <= ok_q[k-1];
    for (int k = 8; k <= 10; k++) peak_q[k] <= peak_q[k-1];
  end

  // Stages 4..10: window sums, training sum of the kind (stage 5), CUT * 2^SCALE_FRAC >
  // S * scale (stage 10)
  logic [SUM_W-1:0] sum5;
  logic             over10;
  cfar_sums #(.PD(PD), .GUARD_D(GUARD_D), .POW_W(POW_W), .SUM_W(SUM_W), .VS_W(VS_W),
              .S_W(S_W), .SCALE_W(SCALE_W), .SCALE_FRAC(SCALE_FRAC),
              .CA_ONLY(BUILT[2:1] == 2'b00)) u_sums (
    .clk(clk), .ev4(ev4), .first4(first4_q), .s3(s_q3), .vo4(vo4_q), .vi4(vi4_q),
    .kind(kind_q), .cut5(cut5),
    .scale5(cfg_scale[e_q[5] * SCALE_W +: SCALE_W]), .sum5(sum5), .over10(over10)
  );

  // OS: stages 2..9 (the window's column words, comparators, popcount, count >= k)
  logic os_q [10:10];
  if (OS_BUILD) begin : g_os
    logic os9;
    cfar_os #(.ROWS(ROWS), .NE(NE), .PR(PR), .PD(PD), .GUARD_R(GUARD_R), .GUARD_D(GUARD_D),
              .POW_W(POW_W), .CNT_W(CNT_W), .SCALE_W(SCALE_W), .SCALE_FRAC(SCALE_FRAC),
              .OS_RANK(OS_RANK)) u_os (
      .clk(clk), .cw2(cw2_q), .mo2(mo2_q), .mi2(mi2_q), .e2(e_q[2]), .ev4(ev4),
      .vcut4(vcut4_q), .cfg_scale(cfg_scale), .os9(os9)
    );
    always_ff @(posedge clk) os_q[10] <= os9;
  end else begin : g_no_os
    assign os_q[10] = 1'b0;
  end

  // Stage 10: the decision of the kind, and the local maximum when it is on
  logic det10;
  assign det10 = ok_q[10] && ((kind_q == 2'd3) ? os_q[10] : over10) && (!lm_q || peak_q[10]);

  // output cells (rows' cells from step 2*PD on) down the pipeline, for the detection count
  logic [10:5] o_q;

  // ---------------------------------------------------------------------------------------
  // Sequencing registers
  always_ff @(posedge clk) begin
    if (rst) begin
      p_q         <= '0;
      s_q         <= '0;
      slot_q      <= '0;
      v_q         <= '0;
      o_q         <= '0;
      st_wr1_q    <= 1'b0;
      st_wr2_q    <= 1'b0;
      framing_q   <= 1'b0;
      frame_cnt_q <= '0;
      det_cnt_q   <= '0;
    end else begin
      v_q      <= {v_q[3:1], step};
      o_q      <= {o_q[9:5], v_q[4] && out_q[4]};
      st_wr1_q <= step && in_phase;
      st_wr2_q <= st_wr1_q;
      if (step && in_phase && (s_axis_tlast != (s_q == S_W'(N_DOPPLER - 1)))) framing_q <= 1'b1;
      if (o_q[10] && det10 && det_cnt_q != '1) det_cnt_q <= det_cnt_q + 1'b1;
      if (step) begin
        if (pass_end) begin
          s_q <= '0;
          if (p_q == P_W'(NPASS - 1)) begin
            p_q         <= '0;
            slot_q      <= '0;
            frame_cnt_q <= frame_cnt_q + 1'b1;
          end else begin
            p_q    <= p_q + 1'b1;
            slot_q <= (slot_q == SLOT_W'(ROWS - 1)) ? '0 : slot_q + 1'b1;
          end
        end else begin
          s_q <= s_q + 1'b1;
        end
      end
    end
  end

  // ---------------------------------------------------------------------------------------
  // Output FIFOs: one entry per tested cell, issued with the step that reads its last
  // column. Two FIFOs in lockstep (same issues, same pops): the early one takes the cell's
  // data and training sum at stage LAT_E, the late one its decision at LAT_L and gives the
  // port its valid, so neither the cell data nor the sum travel down the multiplier's
  // stages. DEPTH >= LAT_L + 2 keeps one cell per clock.
  localparam int FE = 1 + BR + BD + 4 * POW_W + CNT_W + SUM_W + POW_W;
  logic          issue, e_can_issue, e_valid, fl_det;
  logic [FE-1:0] fe_data;
  assign issue = step && testing && (s_q >= S_W'(2 * PD));

  buf_out_fifo #(.WIDTH(FE), .DEPTH(16), .LATENCY(LAT_E)) u_out_early (
    .clk           (clk),
    .rst           (rst),
    .can_issue     (e_can_issue),
    .issue         (issue),
    .in_data       ({last5_q, r_q[5], d_q[5], nb_dp5, nb_dm5, nb_rp5, nb_rm5,
                     cnt_q[5], sum5, cut5}),
    .m_axis_tdata  (fe_data),
    .m_axis_tvalid (e_valid),
    .m_axis_tready (m_axis_tvalid && m_axis_tready)
  );
  buf_out_fifo #(.WIDTH(1), .DEPTH(16), .LATENCY(LAT_L)) u_out (
    .clk           (clk),
    .rst           (rst),
    .can_issue     (can_issue),
    .issue         (issue),
    .in_data       (det10),
    .m_axis_tdata  (fl_det),
    .m_axis_tvalid (m_axis_tvalid),
    .m_axis_tready (m_axis_tready)
  );
  // {pow(r, d+1), pow(r, d-1), pow(r+1, d), pow(r-1, d), detect, count, sum, power}
  assign m_axis_tdata = OUT_W'({fe_data[POW_W + SUM_W + CNT_W +: 4 * POW_W], fl_det,
                                fe_data[POW_W + SUM_W + CNT_W - 1:0]});
  assign m_axis_tuser = fe_data[FE-2 -: BR + BD];
  assign m_axis_tlast = fe_data[FE-1];

  assign status_framing_error = framing_q;
  assign frame_count          = frame_cnt_q;
  assign detection_count      = det_cnt_q;

  // input padding bits are not used (the slot masks only by the OS test, the settings not
  // in a build without their choice)
  logic unused_ok;
  assign unused_ok = ^{s_axis_tdata, e_can_issue, e_valid, mo2_q, mi2_q, cfg_kind,
                       cfg_local_max};

  // AXI4-Stream protocol on every port (rtl/common/axis_checker.sv)
  axis_checker #(.PAYLOAD_W(IN_W + 1), .ASSUME(1'b1)) u_chk_s_axis (
    .clk, .rst, .tvalid(s_axis_tvalid), .tready(s_axis_tready),
    .payload({s_axis_tlast, s_axis_tdata}));
  axis_checker #(.PAYLOAD_W(OUT_W + 1 + $clog2(N_RANGE) + $clog2(N_DOPPLER))) u_chk_m_axis (
    .clk, .rst, .tvalid(m_axis_tvalid), .tready(m_axis_tready),
    .payload({m_axis_tuser, m_axis_tlast, m_axis_tdata}));

endmodule

`default_nettype wire
