// SPDX-License-Identifier: Apache-2.0
// Detection record packetizer: holds the Doppler-FFT words of the last SNAP_ROWS range rows
// (the snapshots) while the CFAR decides, and per detected cell sends one record (header +
// the NUM_TX words of NUM_RX complex values of that cell), then a per-frame trailer with the
// record count and the truncated flag, then zero padding to a fixed FRAME_WORDS so the
// stream can go through axis_packetizer (header/sequence framing, loss detection).
// Records per frame: at most cfg_max_detections (1..MAX_DETECTIONS, a run-time setting
// taken with the frame's first cell and held for the frame); the frame length stays the one
// MAX_DETECTIONS fixes, which the trailer reports beside the frame's limit.
//
// Record and trailer layout: docs/detect.md and model/detect_records.py (the host decoder
// uses that model). Header vector: 16 lanes of 32 bits sent as HDR_WORDS = ceil(16/NUM_RX)
// words (lanes beyond 16 are zero); lanes 8..15 of a record carry the CFAR's four neighbour
// powers of the cell (range -1/+1, Doppler -1/+1) for the host's peak interpolation.
// Snapshot ring: written from the Doppler-FFT stream (order r, t, d) through the snap_*
// port; snap_room is low while the writer is SNAP_ROWS rows ahead of the row the CFAR cells
// come from, so a snapshot is never overwritten before its cell was decided (the parent
// gates the Doppler-FFT stream with it).
`default_nettype none

module detect_records #(
  // TDM transmit slots, 1..16.
  parameter int NUM_TX = 1,
  // Receive lanes per word (32-bit {Q,I} each), 1..64.
  parameter int NUM_RX = 4,
  // Range bins per frame, power of two, 4..4096.
  parameter int N_RANGE = 64,
  // Doppler bins, power of two, 4..4096.
  parameter int N_DOPPLER = 256,
  // Widths of the CFAR cell fields (cfar_2d POW_W, SUM_W, CNT_W), each 1..64.
  parameter int POW_W = 34,
  parameter int SUM_W = 42,
  parameter int CNT_W = 8,
  // Range rows held in the snapshot ring, power of two >= GUARD_R + TRAIN_R + 3 of the CFAR.
  parameter int SNAP_ROWS = 16,
  // Records per frame at most, 1..65535; further detections are counted, flagged, not sent.
  parameter int MAX_DETECTIONS = 256,
  // Derived, do not override: CFAR cell tdata width, header words, record words, frame words.
  parameter int CELL_W = ((5 * POW_W + SUM_W + CNT_W + 1 + 7) / 8) * 8,
  parameter int HDR_WORDS = (16 + NUM_RX - 1) / NUM_RX,
  parameter int REC_WORDS = HDR_WORDS + NUM_TX,
  parameter int FRAME_WORDS = MAX_DETECTIONS * REC_WORDS + HDR_WORDS
) (
  input  wire logic                        clk,
  input  wire logic                        rst,
  // Records per frame at most, 1..MAX_DETECTIONS, sampled with a frame's first cell
  input  wire logic [15:0]                 cfg_max_detections,
  // Snapshot write port: Doppler-FFT words in (r, t, d) order, written when snap_wr
  input  wire logic                        snap_wr,
  input  wire logic [NUM_RX*32-1:0]        snap_data,
  output logic                             snap_room,     // a word may be written now
  // CFAR cells (cfar_2d output): tdata = {4 neighbour powers, detect, count, sum, power},
  // tuser = {r, d}
  input  wire logic [CELL_W-1:0]           s_axis_tdata,
  input  wire logic                        s_axis_tvalid,
  output logic                             s_axis_tready,
  input  wire logic [$clog2(N_RANGE)+$clog2(N_DOPPLER)-1:0] s_axis_tuser,
  // Records: FRAME_WORDS words per frame, TLAST on the last one
  output logic      [NUM_RX*32-1:0]        m_axis_tdata,
  output logic                             m_axis_tvalid,
  input  wire logic                        m_axis_tready,
  output logic                             m_axis_tlast,
  // Status (cleared only by rst)
  output logic                             status_truncated,  // sticky: a frame had more
                                                              // than its limit
  output logic      [31:0]                 frame_count        // frames of records sent
);

  localparam int WORD_W = NUM_RX * 32;
  localparam int BR     = $clog2(N_RANGE);
  localparam int BD     = $clog2(N_DOPPLER);
  localparam int BT     = (NUM_TX > 1) ? $clog2(NUM_TX) : 0;
  localparam int BS     = $clog2(SNAP_ROWS);
  localparam int AW     = BS + BT + BD;
  localparam int G_W    = 16;                              // global row counters
  localparam int RC_W   = 17;                              // record counts
  localparam int FW_W   = $clog2(FRAME_WORDS + 1);
  localparam int HV_W   = ((16 > NUM_RX) ? 16 : NUM_RX) * 32;  // header vector, >= 16 lanes
  localparam int NB_LSB = POW_W + SUM_W + CNT_W + 1;         // first neighbour power bit
  localparam int HS_W   = (HDR_WORDS > 1) ? $clog2(HDR_WORDS) : 1;
  localparam int TS_W   = (NUM_TX > 1) ? $clog2(NUM_TX) : 1;

  // Parameter checks: stop elaboration on illegal values.
  if (NUM_TX < 1 || NUM_TX > 16) begin : g_bad_num_tx
    $fatal(1, "%m: NUM_TX=%0d not in 1..16", NUM_TX);
  end
  if (NUM_RX < 1 || NUM_RX > 64) begin : g_bad_num_rx
    $fatal(1, "%m: NUM_RX=%0d not in 1..64", NUM_RX);
  end
  if (N_RANGE < 4 || N_RANGE > 4096 || (1 << BR) != N_RANGE) begin : g_bad_n_range
    $fatal(1, "%m: N_RANGE=%0d must be a power of two in 4..4096",
           N_RANGE);
  end
  if (N_DOPPLER < 4 || N_DOPPLER > 4096 || (1 << BD) != N_DOPPLER) begin : g_bad_n_doppler
    $fatal(1, "%m: N_DOPPLER=%0d must be a power of two in 4..4096",
           N_DOPPLER);
  end
  if (POW_W < 1 || POW_W > 62 || SUM_W < 1 || SUM_W > 64 || CNT_W < 1 || CNT_W > 16)
  begin : g_bad_cell_w
    $fatal(1, "%m: POW_W=%0d must be 1..62, SUM_W=%0d 1..64, CNT_W=%0d 1..16",
           POW_W, SUM_W, CNT_W);
  end
  if (SNAP_ROWS < 4 || SNAP_ROWS > 64 || (1 << BS) != SNAP_ROWS) begin : g_bad_snap_rows
    $fatal(1, "%m: SNAP_ROWS=%0d must be a power of two in 4..64",
           SNAP_ROWS);
  end
  if (MAX_DETECTIONS < 1 || MAX_DETECTIONS > 65535) begin : g_bad_max_detections
    $fatal(1, "%m: MAX_DETECTIONS=%0d not in 1..65535",
           MAX_DETECTIONS);
  end
  if (HDR_WORDS != (16 + NUM_RX - 1) / NUM_RX || REC_WORDS != HDR_WORDS + NUM_TX ||
      FRAME_WORDS != MAX_DETECTIONS * REC_WORDS + HDR_WORDS ||
      CELL_W != ((5 * POW_W + SUM_W + CNT_W + 1 + 7) / 8) * 8) begin : g_bad_derived
    $fatal(1, "%m: CELL_W/HDR_WORDS/REC_WORDS/FRAME_WORDS are derived");
  end

  // ---------------------------------------------------------------------------------------
  // Snapshot ring: address {global row mod SNAP_ROWS, t, d} (t in clog2(NUM_TX) bits: a TX
  // count that is not a power of two leaves slots t >= NUM_TX of each row unused)
  logic [G_W-1:0] wg_q, rg_q;          // writer / reader global range rows
  logic [BD-1:0]  wd_q;
  logic [TS_W-1:0] wt_q;
  logic [AW-1:0]  snap_wr_addr, snap_rd_addr;
  logic           snap_rd_en;
  logic [WORD_W-1:0] snap_rd_data;
  logic           w_last_tx;

  assign snap_room = ((wg_q - rg_q) < G_W'(SNAP_ROWS));
  assign w_last_tx = (NUM_TX == 1) || (wt_q == TS_W'(NUM_TX - 1));
  if (NUM_TX > 1) begin : g_wa_tx
    assign snap_wr_addr = {wg_q[BS-1:0], wt_q[BT-1:0], wd_q};
  end else begin : g_wa_1
    assign snap_wr_addr = {wg_q[BS-1:0], wd_q};
  end

  buf_sdp_ram #(.WIDTH(WORD_W), .DEPTH(1 << AW)) u_snap (
    .clk     (clk),
    .wr_en   (snap_wr),
    .wr_addr (snap_wr_addr),
    .wr_data (snap_data),
    .rd_en   (snap_rd_en),
    .rd_addr (snap_rd_addr),
    .rd_data (snap_rd_data)
  );

  // ---------------------------------------------------------------------------------------
  // Cell side: a detected cell is latched and its record sent before the next cell
  typedef enum logic [1:0] {S_CELL, S_REC, S_TRAILER, S_PAD} state_t;
  state_t           state_q;
  logic [POW_W-1:0] c_pow_q;
  logic [4*POW_W-1:0] c_nb_q;          // neighbour powers, field k at k*POW_W
  logic [SUM_W-1:0] c_sum_q;
  logic [CNT_W-1:0] c_cnt_q;
  logic [BR-1:0]    c_r_q;
  logic [BD-1:0]    c_d_q;
  logic [HS_W-1:0]  hw_q;              // header word index
  logic [TS_W-1:0]  st_q;              // snapshot word index (TX)
  logic             in_hdr_q;
  logic [RC_W-1:0]  n_rec_q, n_det_q;  // records sent / detections found, this frame
  logic [15:0]      lim_q;             // this frame's record limit (from its first cell)
  logic [RC_W-1:0]  limit;
  logic [BR+BD-1:0] cell_q;            // cells of this frame consumed
  logic [FW_W-1:0]  out_q;             // words of this frame issued
  logic [31:0]      frame_q;
  logic             trunc_q, sticky_q, frame_end_q;
  logic             can_issue, issue, cell_beat, det, last_word;
  logic [POW_W-1:0] s_pow;
  logic [SUM_W-1:0] s_sum;
  logic [CNT_W-1:0] s_cnt;

  assign s_pow = s_axis_tdata[POW_W-1:0];
  assign s_sum = s_axis_tdata[POW_W +: SUM_W];
  assign s_cnt = s_axis_tdata[POW_W + SUM_W +: CNT_W];
  assign det   = s_axis_tdata[POW_W + SUM_W + CNT_W];
  assign s_axis_tready = (state_q == S_CELL);
  assign cell_beat     = s_axis_tvalid && s_axis_tready;
  assign issue         = can_issue && (state_q != S_CELL);
  assign last_word     = (out_q == FW_W'(FRAME_WORDS - 1));
  // the limit: cfg_max_detections with the frame's first cell, then held
  assign limit         = RC_W'((cell_q == '0) ? cfg_max_detections : lim_q);

  // Header vectors (docs/detect.md)
  logic [HV_W-1:0] rec_hdr, trl_hdr, hdr_vec;
  always_comb begin
    rec_hdr = '0;
    rec_hdr[31:0]    = {8'hD1, 12'(c_r_q), 12'(c_d_q)};
    rec_hdr[63:32]   = {16'(n_rec_q), 16'(c_cnt_q)};
    rec_hdr[127:64]  = 64'(c_pow_q);
    rec_hdr[191:128] = 64'(c_sum_q);
    rec_hdr[223:192] = frame_q;
    for (int k = 0; k < 4; k++)
      rec_hdr[256 + 64 * k +: 64] = 64'(c_nb_q[k * POW_W +: POW_W]);
    trl_hdr = '0;
    trl_hdr[31:0]    = {8'hDE, 22'd0, sticky_q, trunc_q};
    trl_hdr[63:32]   = 32'(n_rec_q);
    trl_hdr[95:64]   = 32'(n_det_q);
    trl_hdr[127:96]  = frame_q;
    trl_hdr[159:128] = 32'(MAX_DETECTIONS);
    trl_hdr[191:160] = 32'(lim_q);
    hdr_vec = (state_q == S_TRAILER) ? trl_hdr : rec_hdr;
  end

  // Word issued this clock: header word hw_q, snapshot word st_q (RAM) or padding
  logic [WORD_W-1:0] hdr_word;
  logic              use_ram, p_ram_q, p_last_q;
  logic [WORD_W-1:0] p_word_q;
  assign hdr_word   = hdr_vec[hw_q * WORD_W +: WORD_W];
  assign use_ram    = (state_q == S_REC) && !in_hdr_q;
  assign snap_rd_en = issue && use_ram;
  if (NUM_TX > 1) begin : g_ra_tx
    assign snap_rd_addr = {rg_q[BS-1:0], st_q[BT-1:0], c_d_q};
  end else begin : g_ra_1
    assign snap_rd_addr = {rg_q[BS-1:0], c_d_q};
  end

  always_ff @(posedge clk) begin
    p_ram_q  <= use_ram;
    p_last_q <= last_word;
    p_word_q <= (state_q == S_PAD) ? '0 : hdr_word;
  end

  logic [WORD_W:0] fifo_tdata;
  buf_out_fifo #(.WIDTH(WORD_W + 1), .DEPTH(4)) u_out (
    .clk           (clk),
    .rst           (rst),
    .can_issue     (can_issue),
    .issue         (issue),
    .in_data       ({p_last_q, p_ram_q ? snap_rd_data : p_word_q}),
    .m_axis_tdata  (fifo_tdata),
    .m_axis_tvalid (m_axis_tvalid),
    .m_axis_tready (m_axis_tready)
  );
  assign m_axis_tdata = fifo_tdata[WORD_W-1:0];
  assign m_axis_tlast = fifo_tdata[WORD_W];

  // ---------------------------------------------------------------------------------------
  always_ff @(posedge clk) begin
    if (cell_beat) begin
      c_pow_q <= s_pow;
      c_nb_q  <= s_axis_tdata[NB_LSB +: 4 * POW_W];
      c_sum_q <= s_sum;
      c_cnt_q <= s_cnt;
      c_r_q   <= s_axis_tuser[BD +: BR];
      c_d_q   <= s_axis_tuser[BD-1:0];
    end
  end

  always_ff @(posedge clk) begin
    if (rst) begin
      wg_q        <= '0;
      wd_q        <= '0;
      wt_q        <= '0;
      rg_q        <= '0;
      state_q     <= S_CELL;
      hw_q        <= '0;
      st_q        <= '0;
      in_hdr_q    <= 1'b1;
      lim_q       <= 16'(MAX_DETECTIONS);
      n_rec_q     <= '0;
      n_det_q     <= '0;
      cell_q      <= '0;
      out_q       <= '0;
      frame_q     <= '0;
      trunc_q     <= 1'b0;
      sticky_q    <= 1'b0;
      frame_end_q <= 1'b0;
    end else begin
      // snapshot writer
      if (snap_wr) begin
        wd_q <= wd_q + 1'b1;
        if (wd_q == '1) begin
          wt_q <= w_last_tx ? '0 : wt_q + 1'b1;
          if (w_last_tx) wg_q <= wg_q + 1'b1;
        end
      end
      unique case (state_q)
        S_CELL: if (cell_beat) begin
          cell_q      <= cell_q + 1'b1;
          frame_end_q <= (cell_q == '1);
          if (cell_q == '0) lim_q <= cfg_max_detections;
          if (det) begin
            if (n_det_q != '1) n_det_q <= n_det_q + 1'b1;
            if (n_rec_q == limit) begin
              trunc_q  <= 1'b1;
              sticky_q <= 1'b1;
            end
          end
          if (det && n_rec_q != limit) begin
            state_q  <= S_REC;
            hw_q     <= '0;
            st_q     <= '0;
            in_hdr_q <= 1'b1;
          end else begin
            if (cell_q[BD-1:0] == '1) rg_q <= rg_q + 1'b1;
            if (cell_q == '1) begin
              state_q <= S_TRAILER;
              hw_q    <= '0;
            end
          end
        end
        S_REC: if (issue) begin
          out_q <= out_q + 1'b1;
          if (in_hdr_q) begin
            if (hw_q == HS_W'(HDR_WORDS - 1)) in_hdr_q <= 1'b0;
            else hw_q <= hw_q + 1'b1;
          end else if (st_q == TS_W'(NUM_TX - 1)) begin
            n_rec_q <= n_rec_q + 1'b1;
            // the cell is done: advance the row and close the frame as in S_CELL
            if (cell_q[BD-1:0] == '0) rg_q <= rg_q + 1'b1;
            state_q <= frame_end_q ? S_TRAILER : S_CELL;
            hw_q    <= '0;
          end else begin
            st_q <= st_q + 1'b1;
          end
        end
        S_TRAILER: if (issue) begin
          out_q <= out_q + 1'b1;
          if (hw_q == HS_W'(HDR_WORDS - 1)) state_q <= S_PAD;
          else hw_q <= hw_q + 1'b1;
          if (last_word) state_q <= S_CELL;
        end
        default: if (issue) begin       // S_PAD
          out_q <= out_q + 1'b1;
          if (last_word) state_q <= S_CELL;
        end
      endcase
      // frame closed: the last word of the frame was issued
      if (issue && last_word) begin
        out_q    <= '0;
        n_rec_q  <= '0;
        n_det_q  <= '0;
        trunc_q  <= 1'b0;
        frame_q  <= frame_q + 1'b1;
        state_q  <= S_CELL;
      end
    end
  end

  assign status_truncated = sticky_q;
  assign frame_count      = frame_q;

`ifndef SYNTHESIS
  // block invariant: the snapshot ring is never written without room
  always_ff @(posedge clk) begin
    if (!rst && snap_wr) assert (snap_room) else $error("%m: snapshot written without room");
    if (!rst && cell_beat && cell_q == '0)
      assert (cfg_max_detections != '0 && 32'(cfg_max_detections) <= 32'(MAX_DETECTIONS))
        else $error("%m: cfg_max_detections=%0d not in 1..%0d", cfg_max_detections,
                    MAX_DETECTIONS);
  end
`endif

  // AXI4-Stream protocol on every port (rtl/common/axis_checker.sv)
  axis_checker #(.PAYLOAD_W(CELL_W + $clog2(N_RANGE) + $clog2(N_DOPPLER)), .ASSUME(1'b1)) u_chk_s_axis (
    .clk, .rst, .tvalid(s_axis_tvalid), .tready(s_axis_tready),
    .payload({s_axis_tuser, s_axis_tdata}));
  axis_checker #(.PAYLOAD_W(NUM_RX*32 + 1)) u_chk_m_axis (
    .clk, .rst, .tvalid(m_axis_tvalid), .tready(m_axis_tready),
    .payload({m_axis_tlast, m_axis_tdata}));

endmodule

`default_nettype wire
