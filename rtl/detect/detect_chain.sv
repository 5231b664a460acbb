// SPDX-License-Identifier: Apache-2.0
// On-chip detection (radar_pipeline OUTPUT_MODE = 1): Doppler-FFT words in, detection
// records out. nci (|x|^2 over NUM_TX x NUM_RX) -> cfar_2d -> detect_records, whose
// snapshot ring is written from the same input stream. The record stream has a fixed
// FRAME_WORDS per frame, ready for axis_packetizer (header, sequence numbers, loss flags).
// Run-time settings (cfg_scale, cfg_kind, cfg_local_max, cfg_max_detections) change only in
// the cycle after a frame_start pulse: the CFAR takes the first word of a frame's range
// row 1. By then the CFAR has tested every row of the previous frame (it tests a frame's
// last rows before it takes the next frame's input, and its pipeline reads the scale 6 and
// the kind / local maximum at most 9 clocks after a step, fewer than the N_DOPPLER >= 8
// steps of row 0 before the pulse; the top has >= 16), and it tests no row of
// the new frame before it takes row GUARD_R+TRAIN_R+1; detect_records takes the record
// limit with a frame's first cell, which comes after that pulse too.
// Formats and the pass schedule: docs/detect.md; model: model/detect_chain.py.
`default_nettype none

module detect_chain #(
  // TDM transmit slots, 1..16.
  parameter int NUM_TX = 1,
  // Receive lanes per word (32-bit {Q,I}), 1..64.
  parameter int NUM_RX = 4,
  // Range bins, power of two, 4..4096.
  parameter int N_RANGE = 64,
  // Doppler bins, power of two, 4..4096.
  parameter int N_DOPPLER = 256,
  // CFAR window: guard / training cells per side along range (R) and Doppler (D).
  parameter int GUARD_R = 2,
  parameter int GUARD_D = 2,
  parameter int TRAIN_R = 4,
  parameter int TRAIN_D = 8,
  // Default CFAR kind: 0 CA, 1 GO, 2 SO, 3 OS (builds the OS test); RUN_KINDS: the kinds
  // CA/GO/SO cfg_kind may select; OS_BUILD: build OS with another default kind; OS_RANK: OS
  // rank per mille; LOCAL_MAX_BUILD: build the local-maximum test (cfar_2d).
  parameter int KIND = 0,
  parameter logic [2:0] RUN_KINDS = 3'b111,
  parameter bit OS_BUILD = (KIND == 3),
  parameter int OS_RANK = 750,
  parameter bit LOCAL_MAX_BUILD = 1'b1,
  // Top range bins blanked (negative beat frequencies), see cfar_2d.
  parameter int BLANK_TOP = 0,
  // Range rows that may report detections, REPORT_LO <= r < REPORT_HI (cfar_2d).
  parameter int REPORT_LO = 0,
  parameter int REPORT_HI = N_RANGE,
  // Threshold scale fixed point (cfar_2d).
  parameter int SCALE_W = 32,
  parameter int SCALE_FRAC = 20,
  // Records per frame at most, 1..65535.
  parameter int MAX_DETECTIONS = 256,
  // Derived, do not override.
  parameter int POW_W = 32 + $clog2(NUM_TX * NUM_RX),
  parameter int FRAME_WORDS = MAX_DETECTIONS * ((8 + NUM_RX - 1) / NUM_RX + NUM_TX)
                              + (8 + NUM_RX - 1) / NUM_RX
) (
  input  wire logic                     clk,
  input  wire logic                     rst,
  // Threshold scale per CFAR edge index (model/cfar_2d.py scale_table); records per frame
  // at most, 1..MAX_DETECTIONS. Change them only in the cycle after frame_start.
  input  wire logic [(2*(GUARD_R+TRAIN_R)+1)*SCALE_W-1:0] cfg_scale,
  input  wire logic [15:0]              cfg_max_detections,
  // CFAR kind 0 CA, 1 GO, 2 SO, 3 OS; the 3x3 local-maximum test on (cfar_2d); change them
  // only in the cycle after frame_start, as cfg_scale
  input  wire logic [1:0]               cfg_kind,
  input  wire logic                     cfg_local_max,
  output logic                          frame_start,   // the settings may change after it
  // Doppler-FFT output in (r, t, d) order, TLAST on Doppler bin N_DOPPLER-1 (checked)
  input  wire logic [NUM_RX*32-1:0]     s_axis_tdata,
  input  wire logic                     s_axis_tvalid,
  output logic                          s_axis_tready,
  input  wire logic                     s_axis_tlast,
  // Records: FRAME_WORDS words per frame, TLAST on the last word of a frame
  output logic      [NUM_RX*32-1:0]     m_axis_tdata,
  output logic                          m_axis_tvalid,
  input  wire logic                     m_axis_tready,
  output logic                          m_axis_tlast,
  // Status (cleared only by rst)
  output logic                          status_framing_error,  // sticky: input TLAST misplaced
  output logic                          status_truncated,      // sticky: > MAX_DETECTIONS
  output logic      [31:0]              detection_count,       // CFAR detections (saturating)
  output logic      [31:0]              frame_count            // record frames sent
);

  localparam int PR   = GUARD_R + TRAIN_R;
  localparam int BR   = $clog2(N_RANGE);
  localparam int BD   = $clog2(N_DOPPLER);
  // snapshot ring: the writer runs up to PR+2 rows ahead of the row the CFAR decides
  localparam int SNAP_ROWS = 1 << $clog2(PR + 3);
  localparam int NCI_W  = ((POW_W + 7) / 8) * 8;
  localparam int CNT_W  = $clog2((2 * PR + 1) * (2 * (GUARD_D + TRAIN_D) + 1));
  localparam int SUM_W  = POW_W + CNT_W;
  localparam int CELL_W = ((5 * POW_W + SUM_W + CNT_W + 1 + 7) / 8) * 8;

  if (POW_W != 32 + $clog2(NUM_TX * NUM_RX) ||
      FRAME_WORDS != MAX_DETECTIONS * ((8 + NUM_RX - 1) / NUM_RX + NUM_TX)
                     + (8 + NUM_RX - 1) / NUM_RX) begin : g_bad_derived
    $fatal(1, "%m: POW_W/FRAME_WORDS are derived, do not override");
  end

  // ---------------------------------------------------------------------------------------
  // Input: NCI and the snapshot ring take every word together
  logic snap_room, nci_ready;
  assign s_axis_tready = nci_ready && snap_room;

  logic [NCI_W-1:0]   nci_tdata;
  logic               nci_tvalid, nci_tready, nci_tlast;
  logic [BR+BD-1:0]   nci_tuser;
  logic [31:0]        nci_frames;

  nci #(.NUM_TX(NUM_TX), .NUM_RX(NUM_RX), .N_RANGE(N_RANGE), .N_DOPPLER(N_DOPPLER),
        .DATA_W(16)) u_nci (
    .clk(clk), .rst(rst),
    .s_axis_tdata(s_axis_tdata), .s_axis_tvalid(s_axis_tvalid && snap_room),
    .s_axis_tready(nci_ready), .s_axis_tlast(s_axis_tlast),
    .m_axis_tdata(nci_tdata), .m_axis_tvalid(nci_tvalid), .m_axis_tready(nci_tready),
    .m_axis_tlast(nci_tlast), .m_axis_tuser(nci_tuser),
    .status_framing_error(status_framing_error), .frame_count(nci_frames)
  );

  logic [CELL_W-1:0]  cf_tdata;
  logic               cf_tvalid, cf_tready, cf_tlast;
  logic [BR+BD-1:0]   cf_tuser;
  logic               cf_framing;
  logic [31:0]        cf_frames;

  cfar_2d #(.N_RANGE(N_RANGE), .N_DOPPLER(N_DOPPLER), .POW_W(POW_W), .GUARD_R(GUARD_R),
            .GUARD_D(GUARD_D), .TRAIN_R(TRAIN_R), .TRAIN_D(TRAIN_D), .KIND(KIND),
            .RUN_KINDS(RUN_KINDS), .OS_BUILD(OS_BUILD), .OS_RANK(OS_RANK),
            .LOCAL_MAX_BUILD(LOCAL_MAX_BUILD), .BLANK_TOP(BLANK_TOP),
            .REPORT_LO(REPORT_LO), .REPORT_HI(REPORT_HI), .SCALE_W(SCALE_W),
            .SCALE_FRAC(SCALE_FRAC)) u_cfar (
    .clk(clk), .rst(rst), .cfg_scale(cfg_scale), .cfg_kind(cfg_kind),
    .cfg_local_max(cfg_local_max),
    .s_axis_tdata(nci_tdata), .s_axis_tvalid(nci_tvalid), .s_axis_tready(nci_tready),
    .s_axis_tlast(nci_tlast),
    .m_axis_tdata(cf_tdata), .m_axis_tvalid(cf_tvalid), .m_axis_tready(cf_tready),
    .m_axis_tlast(cf_tlast), .m_axis_tuser(cf_tuser),
    .status_framing_error(cf_framing), .frame_count(cf_frames),
    .detection_count(detection_count)
  );

  // frame start: the CFAR takes word N_DOPPLER of a frame (the first of range row 1)
  logic [BR+BD-1:0] cin_q;             // CFAR input words of this frame
  always_ff @(posedge clk) begin
    if (rst) cin_q <= '0;
    else if (nci_tvalid && nci_tready) cin_q <= cin_q + 1'b1;
  end
  assign frame_start = nci_tvalid && nci_tready && (cin_q == (BR+BD)'(N_DOPPLER));

  detect_records #(.NUM_TX(NUM_TX), .NUM_RX(NUM_RX), .N_RANGE(N_RANGE),
                   .N_DOPPLER(N_DOPPLER), .POW_W(POW_W), .SUM_W(SUM_W), .CNT_W(CNT_W),
                   .SNAP_ROWS(SNAP_ROWS), .MAX_DETECTIONS(MAX_DETECTIONS)) u_rec (
    .clk(clk), .rst(rst), .cfg_max_detections(cfg_max_detections),
    .snap_wr(s_axis_tvalid && s_axis_tready), .snap_data(s_axis_tdata), .snap_room(snap_room),
    .s_axis_tdata(cf_tdata), .s_axis_tvalid(cf_tvalid), .s_axis_tready(cf_tready),
    .s_axis_tuser(cf_tuser),
    .m_axis_tdata(m_axis_tdata), .m_axis_tvalid(m_axis_tvalid), .m_axis_tready(m_axis_tready),
    .m_axis_tlast(m_axis_tlast),
    .status_truncated(status_truncated), .frame_count(frame_count)
  );

  // internal framing is by construction (nci and cfar_2d count the same frames)
  logic unused_ok;
  assign unused_ok = ^{nci_frames, nci_tuser, cf_tlast, cf_framing, cf_frames};

endmodule

`default_nettype wire
