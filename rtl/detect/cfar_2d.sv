// SPDX-License-Identifier: Apache-2.0
// 2-D CFAR on the integrated power map: cell averaging (CA), greatest-of (GO) or
// smallest-of (SO), circular in Doppler, training window cut at the range ends with a
// per-edge-row threshold scale, the top BLANK_TOP range bins blanked (never tested, never
// used for training). Streams the map in (for r, for d) and sends every cell out with its
// training sum, training cell count, the detection flag and the powers of its four
// neighbours (range -1/+1, Doppler -1/+1: what the host's peak interpolation needs).
//
// Architecture (docs/detect.md): a column store of N_DOPPLER words, each holding the cells
// of the last ROWS = 2*PR+2 range rows of that Doppler column. Pass p writes input row p
// (read-modify-write, one cell per clock) and tests row q = p-PR-1, whose window rows
// q-PR..q+PR are complete: the vertical sums of every column stream through a shift
// register of 2*PD+1 columns; the circular wrap is closed by replaying columns 0..2*PD-1
// after column N_DOPPLER-1 (2*PD extra clocks per tested row). After the last input row,
// PR+1 passes without input test the remaining rows. Output order per row:
// d = PD..N_DOPPLER-1, 0..PD-1 (every cell carries its {r, d} in tuser).
// Detection: CUT * 2^SCALE_FRAC > S * cfg_scale[e] (exact integers), S the training sum
// of the chosen kind, e the edge index of the row (0..PR-1: PR-e rows cut below,
// PR: interior, PR+1..2*PR: e-PR rows cut above). The scales come from model/cfar_2d.py
// (alpha(Pfa, cells) / cells, the host CFAR's statistics).
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
  // 0: CA (all training cells), 1: GO (greater of the left/right Doppler halves),
  // 2: SO (smaller of the halves). Halves: Doppler offsets < 0 and > 0 (the CUT's own
  // column is not in either half).
  parameter int KIND = 0,
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
  localparam int CW_W  = ROWS * POW_W;               // column word
  localparam int PROD_W = SUM_W + SCALE_W;

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
  if (KIND < 0 || KIND > 2) begin : g_bad_kind
    $fatal(1, "%m: KIND=%0d not 0 (CA), 1 (GO) or 2 (SO)", KIND);
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
  // Column store: word d = cells of column d of the last ROWS rows, slot = row mod ROWS
  logic [CW_W-1:0] cw_rd, cw_wr;
  logic            st_wr_q;
  logic [BD-1:0]   st_col_q;
  logic [SLOT_W-1:0] st_slot_q;
  logic [POW_W-1:0] st_x_q;

  buf_sdp_ram #(.WIDTH(CW_W), .DEPTH(N_DOPPLER)) u_store (
    .clk     (clk),
    .wr_en   (st_wr_q),
    .wr_addr (st_col_q),
    .wr_data (cw_wr),
    .rd_en   (step),
    .rd_addr (col),
    .rd_data (cw_rd)
  );

  // Slot selects are ROWS-way decodes with constant part-selects (a variable part-select
  // of the CW_W-bit word would be a full-width shifter per use)
  always_comb begin
    cw_wr = cw_rd;
    for (int s = 0; s < ROWS; s++)
      if (st_slot_q == SLOT_W'(s)) cw_wr[s * POW_W +: POW_W] = st_x_q;
  end

  // ---------------------------------------------------------------------------------------
  // Row geometry of the tested row q = p - PR - 1, computed at the step, used next clock
  logic [NE-1:0]     rowv;       // window row k (row q-PR+k) exists
  logic [$clog2(NE+1)-1:0] n_out, n_in;   // existing rows: whole window / guard band
  logic [$clog2(NE)-1:0]   e_idx;
  always_comb begin
    int q, row, lo, hi;
    q     = int'(p_q) - PR - 1;
    n_out = '0;
    n_in  = '0;
    for (int k = 0; k < NE; k++) begin
      row     = q - PR + k;
      rowv[k] = (row >= 0) && (row < N_EFF);
      if (rowv[k]) n_out = n_out + 1'b1;
      if (rowv[k] && k >= PR - GUARD_R && k <= PR + GUARD_R) n_in = n_in + 1'b1;
    end
    lo = (q < PR) ? PR - q : 0;                         // rows cut below
    hi = (q + PR > N_EFF - 1) ? q + PR - (N_EFF - 1) : 0;  // rows cut above
    if (hi > PR) hi = PR;                                 // blanked rows (not tested)
    e_idx = $bits(e_idx)'((lo > 0) ? PR - lo : PR + hi);
  end

  // Stage 1 registers (the step's read data arrives with them)
  logic              v1_q, test1_q, out1_q, last1_q, cut_ok1_q, rm_ok1_q, rp_ok1_q;
  logic [NE-1:0]     rowv1_q;
  logic [$clog2(NE+1)-1:0] n_out1_q, n_in1_q;
  logic [$clog2(NE)-1:0]   e1_q;
  logic [BR-1:0]     r1_q;
  logic [BD-1:0]     d1_q;

  always_ff @(posedge clk) begin
    int q;
    q = int'(p_q) - PR - 1;
    st_col_q  <= col;
    st_slot_q <= slot_q;
    st_x_q    <= s_axis_tdata[POW_W-1:0];
    test1_q   <= testing;
    out1_q    <= testing && (s_q >= S_W'(2 * PD));
    last1_q   <= pass_end;
    rowv1_q   <= rowv;
    n_out1_q  <= n_out;
    n_in1_q   <= n_in;
    e1_q      <= e_idx;
    cut_ok1_q <= (q < N_EFF) && (q >= REPORT_LO) && (q < REPORT_HI);
    rm_ok1_q  <= (q >= 1);                 // row q-1 exists
    rp_ok1_q  <= (q + 1 < N_RANGE);        // row q+1 exists
    r1_q      <= BR'(q);
    d1_q      <= BD'(s_q - S_W'(PD));   // centre column (mod N_DOPPLER)
  end

  // ---------------------------------------------------------------------------------------
  // Vertical sums of the arriving column over the tested row's window
  logic [POW_W-1:0] win [NE];     // win[k]: cell of window row q-PR+k (slot (p+1+k) mod ROWS)
  always_comb begin
    for (int k = 0; k < NE; k++) win[k] = '0;
    for (int s = 0; s < ROWS; s++)
      if (st_slot_q == SLOT_W'(s))
        for (int k = 0; k < NE; k++) win[k] = cw_rd[((s + 1 + k) % ROWS) * POW_W +: POW_W];
  end

  logic [SUM_W-1:0] vo, vi;
  logic [POW_W-1:0] vcut;
  always_comb begin
    vo   = '0;
    vi   = '0;
    vcut = '0;
    for (int k = 0; k < NE; k++) begin
      if (rowv1_q[k]) begin
        vo = vo + SUM_W'(win[k]);
        if (k >= PR - GUARD_R && k <= PR + GUARD_R) vi = vi + SUM_W'(win[k]);
      end
      if (k == PR) vcut = win[k];
    end
  end

  // Shift register of the previous 2*PD columns' sums (index 0 = newest), of the previous
  // PD+1 columns' CUT-row cells (the CUT at PD-1, its Doppler neighbours at PD and PD-2)
  // and of the previous PD columns' cells in rows q-1 and q+1 (the CUT's column at PD-1)
  logic [SUM_W-1:0] sr_o [2*PD];
  logic [SUM_W-1:0] sr_i [2*PD];
  logic [POW_W-1:0] sr_c [PD+1];
  logic [POW_W-1:0] sr_rm [PD];
  logic [POW_W-1:0] sr_rp [PD];
  always_ff @(posedge clk) begin
    if (v1_q && test1_q) begin
      sr_o[0]  <= vo;
      sr_i[0]  <= vi;
      sr_c[0]  <= vcut;
      sr_rm[0] <= win[PR-1];
      sr_rp[0] <= win[PR+1];
      for (int k = 1; k < 2 * PD; k++) begin
        sr_o[k] <= sr_o[k-1];
        sr_i[k] <= sr_i[k-1];
      end
      for (int k = 1; k <= PD; k++) sr_c[k] <= sr_c[k-1];
      for (int k = 1; k < PD; k++) begin
        sr_rm[k] <= sr_rm[k-1];
        sr_rp[k] <= sr_rp[k-1];
      end
    end
  end

  // Neighbour powers of the centre cell (Doppler +1 is the arriving column when PD = 1)
  logic [POW_W-1:0] nb_rm, nb_rp, nb_dm, nb_dp;
  assign nb_rm = rm_ok1_q ? sr_rm[PD-1] : '0;
  assign nb_rp = rp_ok1_q ? sr_rp[PD-1] : '0;
  assign nb_dm = sr_c[PD];
  if (PD > 1) begin : g_dp_sr
    assign nb_dp = sr_c[PD-2];
  end else begin : g_dp_arriving
    assign nb_dp = vcut;
  end

  // Window around the centre column (offset j = -PD..PD; j = PD is the arriving column)
  logic [SUM_W-1:0] sum_l, sum_r, sum_c, sum_sel;
  logic [POW_W-1:0] cut;
  logic [CNT_W-1:0] cnt;
  always_comb begin
    logic [SUM_W-1:0] wo, wi;
    sum_l = '0;
    sum_r = '0;
    sum_c = '0;
    // offsets -PD..PD-1 from the shift register (index PD-1-j), offset PD is the arriving
    // column (always a training column: PD > GUARD_D)
    for (int j = -PD; j < PD; j++) begin
      wo = sr_o[PD - 1 - j];
      wi = sr_i[PD - 1 - j];
      if (j < 0) sum_l = sum_l + wo - ((j >= -GUARD_D) ? wi : '0);
      if (j > 0) sum_r = sum_r + wo - ((j <= GUARD_D) ? wi : '0);
      if (j == 0) sum_c = wo - wi;
    end
    sum_r = sum_r + vo;
    cut = sr_c[PD - 1];
    unique case (KIND)
      1:       sum_sel = (sum_l > sum_r) ? sum_l : sum_r;
      2:       sum_sel = (sum_l < sum_r) ? sum_l : sum_r;
      default: sum_sel = sum_l + sum_r + sum_c;
    endcase
    if (KIND == 0)
      cnt = CNT_W'(n_out1_q * (2 * PD + 1) - n_in1_q * (2 * GUARD_D + 1));
    else
      cnt = CNT_W'(n_out1_q * PD - n_in1_q * GUARD_D);
  end

  logic [SCALE_W-1:0] scale;
  logic [PROD_W-1:0]  prod, cut_sh;
  logic               detect;
  assign scale  = cfg_scale[e1_q * SCALE_W +: SCALE_W];
  assign prod   = PROD_W'(sum_sel) * PROD_W'(scale);
  assign cut_sh = PROD_W'(cut) << SCALE_FRAC;
  assign detect = cut_ok1_q && (cut_sh > prod);

  // ---------------------------------------------------------------------------------------
  // Sequencing registers
  always_ff @(posedge clk) begin
    if (rst) begin
      p_q         <= '0;
      s_q         <= '0;
      slot_q      <= '0;
      v1_q        <= 1'b0;
      st_wr_q     <= 1'b0;
      framing_q   <= 1'b0;
      frame_cnt_q <= '0;
      det_cnt_q   <= '0;
    end else begin
      v1_q    <= step;
      st_wr_q <= step && in_phase;
      if (step && in_phase && (s_axis_tlast != (s_q == S_W'(N_DOPPLER - 1)))) framing_q <= 1'b1;
      if (v1_q && out1_q && detect && det_cnt_q != '1) det_cnt_q <= det_cnt_q + 1'b1;
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
  // Output FIFO: one entry per tested cell, the clock after its last column was read
  localparam int FW = 1 + BR + BD + 5 * POW_W + SUM_W + CNT_W + 1;
  logic [FW-1:0] fifo_tdata;

  buf_out_fifo #(.WIDTH(FW), .DEPTH(4)) u_out (
    .clk           (clk),
    .rst           (rst),
    .can_issue     (can_issue),
    .issue         (step && testing && (s_q >= S_W'(2 * PD))),
    .in_data       ({last1_q, r1_q, d1_q, nb_dp, nb_dm, nb_rp, nb_rm, detect, cnt, sum_sel,
                     cut}),
    .m_axis_tdata  (fifo_tdata),
    .m_axis_tvalid (m_axis_tvalid),
    .m_axis_tready (m_axis_tready)
  );
  assign m_axis_tdata = OUT_W'(fifo_tdata[5 * POW_W + SUM_W + CNT_W:0]);
  assign m_axis_tuser = fifo_tdata[FW-2 -: BR + BD];
  assign m_axis_tlast = fifo_tdata[FW-1];

  assign status_framing_error = framing_q;
  assign frame_count          = frame_cnt_q;
  assign detection_count      = det_cnt_q;

  // input padding bits are not used
  logic unused_ok;
  assign unused_ok = ^s_axis_tdata;

  // AXI4-Stream protocol on every port (rtl/common/axis_checker.sv)
  axis_checker #(.PAYLOAD_W(IN_W + 1), .ASSUME(1'b1)) u_chk_s_axis (
    .clk, .rst, .tvalid(s_axis_tvalid), .tready(s_axis_tready),
    .payload({s_axis_tlast, s_axis_tdata}));
  axis_checker #(.PAYLOAD_W(OUT_W + 1 + $clog2(N_RANGE) + $clog2(N_DOPPLER))) u_chk_m_axis (
    .clk, .rst, .tvalid(m_axis_tvalid), .tready(m_axis_tready),
    .payload({m_axis_tuser, m_axis_tlast, m_axis_tdata}));

endmodule

`default_nettype wire
