// SPDX-License-Identifier: Apache-2.0
// External frame store: the corner turn (frame transpose between the range FFT and the Doppler
// FFT) in DDR4 over an AXI4 master port, a drop-in for corner_turn (same AXI4-Stream ports,
// same output order for the same READ_ORDER) when the frame does not fit on chip.
//
// Layout (docs/frame_store.md): two frame areas of FRAME_BYTES from MEM_BASE, frame k in area
// k mod 2. Inside an area the range axis is cut into strips of TILE_R range bins; strip
// (t, s) of TX t is a contiguous block of N_DOPPLER rows, row d holding range bins
// s*TILE_R .. s*TILE_R+TILE_R-1 of chirp d of TX t. The strips follow each other in the
// order the output needs them, S = N_RANGE/TILE_R:
//   READ_ORDER 0 (t, r, d): strip index t*S + s     (a group = one strip)
//   READ_ORDER 1 (r, t, d): strip index s*NUM_TX + t (a group = the NUM_TX strips of s)
//   byte offset of word (t, d, r) = (strip index * N_DOPPLER + d)*TILE_R*WORD_B
//                                   + (r mod TILE_R)*WORD_B.
// Write side: each chirp is written as S INCR bursts of one row (TILE_R words, aligned, so
// never across 4 KiB) straight from a small FIFO. Read side: the frame area is read linearly
// (INCR bursts of the largest power of two dividing the group, at most 4 KiB) into a
// two-group on-chip buffer (each half a power of two of entries), and each group leaves as
// TILE_R (order 0) or TILE_R*NUM_TX (order 1) Doppler vectors. Frame k+1 is written while frame k is read; the writer
// starts frame k+2 only once frame k has been read back, the reader starts frame k only once
// every write of frame k has its BRESP. Memory slower than the input fills the FIFO and
// drops s_axis_tready: the back-pressure reaches the chirp ping-pong, which drops whole
// chirps (flagged there), never a sample here.
`default_nettype none

module frame_store_axi #(
  // TX slots (TDM chirps interleaved), 1..16.
  parameter int NUM_TX = 1,
  // Receive lanes per word, power of two, 1..16.
  parameter int NUM_RX = 4,
  // Range bins per chirp (words per input chirp), power of two, 2..4096.
  parameter int N_RANGE = 64,
  // Chirps per TX per frame (output Doppler vector length), power of two, 2..4096.
  parameter int N_DOPPLER = 256,
  // Output order of the Doppler vectors (corner_turn's READ_ORDER): 0 = (t, r, d), the DMA
  // cube order; 1 = (r, t, d), all TX of a range bin together (on-chip detection). The
  // on-chip read buffer holds two groups: 2*TILE_R*N_DOPPLER words (order 0) or NUM_TX
  // times that (order 1).
  parameter int READ_ORDER = 0,
  // Bits of I and of Q per lane: 8, 16 or 32.
  parameter int DATA_W = 16,
  // Range bins per strip (one write burst = TILE_R words), power of two, 1..N_RANGE, with
  // TILE_R*NUM_RX*2*DATA_W a multiple of AXI_DATA_W and at most 4 KiB.
  parameter int TILE_R = 16,
  // AXI4 data width in bits: 128, 256 or 512.
  parameter int AXI_DATA_W = 128,
  // AXI4 address width in bits, 32..40.
  parameter int AXI_ADDR_W = 32,
  // AXI4 ID width in bits, 1..8 (the store uses ID 0 only: responses arrive in order).
  parameter int AXI_ID_W = 1,
  // Byte address of the two frame areas, 4 KiB aligned; the areas must fit in AXI_ADDR_W.
  // (waiver: command-line overrides such as -GMEM_BASE=4096 arrive as 32-bit constants)
  /* verilator lint_off WIDTHEXPAND */
  parameter longint unsigned MEM_BASE = 0,
  /* verilator lint_on WIDTHEXPAND */
  // AXI4 transactions outstanding per direction (AW without B, AR without last R), 1..32.
  parameter int MAX_OUTSTANDING = 8,
  // Write FIFO entries (max(word, AXI beat) wide), power of two, 4..1024, at least two write
  // bursts (an AW is issued only once its whole burst waits in the FIFO).
  parameter int WFIFO_DEPTH = 64
) (
  input  wire logic                          clk,
  input  wire logic                          rst,
  // Range FFT output: chirp by chirp, TLAST on range bin N_RANGE-1 of every chirp
  input  wire logic [NUM_RX*2*DATA_W-1:0]    s_axis_tdata,
  input  wire logic                          s_axis_tvalid,
  output logic                               s_axis_tready,
  input  wire logic                          s_axis_tlast,
  // Doppler vectors: for TX t, for range bin r (READ_ORDER 0; order 1: for r, for t),
  // N_DOPPLER words (chirps of TX t in order), TLAST on the last word of every vector,
  // TUSER[0] on the first word of every frame
  output logic      [NUM_RX*2*DATA_W-1:0]    m_axis_tdata,
  output logic                               m_axis_tvalid,
  input  wire logic                          m_axis_tready,
  output logic                               m_axis_tlast,
  output logic      [0:0]                    m_axis_tuser,
  // AXI4 master to the frame memory
  output logic      [AXI_ID_W-1:0]           m_axi_mem_awid,
  output logic      [AXI_ADDR_W-1:0]         m_axi_mem_awaddr,
  output logic      [7:0]                    m_axi_mem_awlen,
  output logic      [2:0]                    m_axi_mem_awsize,
  output logic      [1:0]                    m_axi_mem_awburst,
  output logic                               m_axi_mem_awlock,
  output logic      [3:0]                    m_axi_mem_awcache,
  output logic      [2:0]                    m_axi_mem_awprot,
  output logic                               m_axi_mem_awvalid,
  input  wire logic                          m_axi_mem_awready,
  output logic      [AXI_DATA_W-1:0]         m_axi_mem_wdata,
  output logic      [AXI_DATA_W/8-1:0]       m_axi_mem_wstrb,
  output logic                               m_axi_mem_wlast,
  output logic                               m_axi_mem_wvalid,
  input  wire logic                          m_axi_mem_wready,
  input  wire logic [AXI_ID_W-1:0]           m_axi_mem_bid,
  input  wire logic [1:0]                    m_axi_mem_bresp,
  input  wire logic                          m_axi_mem_bvalid,
  output logic                               m_axi_mem_bready,
  output logic      [AXI_ID_W-1:0]           m_axi_mem_arid,
  output logic      [AXI_ADDR_W-1:0]         m_axi_mem_araddr,
  output logic      [7:0]                    m_axi_mem_arlen,
  output logic      [2:0]                    m_axi_mem_arsize,
  output logic      [1:0]                    m_axi_mem_arburst,
  output logic                               m_axi_mem_arlock,
  output logic      [3:0]                    m_axi_mem_arcache,
  output logic      [2:0]                    m_axi_mem_arprot,
  output logic                               m_axi_mem_arvalid,
  input  wire logic                          m_axi_mem_arready,
  input  wire logic [AXI_ID_W-1:0]           m_axi_mem_rid,
  input  wire logic [AXI_DATA_W-1:0]         m_axi_mem_rdata,
  input  wire logic [1:0]                    m_axi_mem_rresp,
  input  wire logic                          m_axi_mem_rlast,
  input  wire logic                          m_axi_mem_rvalid,
  output logic                               m_axi_mem_rready,
  // Status (cleared only by rst)
  output logic                               status_framing_error, // sticky: misplaced TLAST
  output logic      [31:0]                   framing_error_count,  // misplaced/missing TLASTs
  output logic                               status_mem_error,     // sticky: SLVERR/DECERR or
                                                                   // RLAST out of place
  output logic      [31:0]                   mem_error_count,      // error B + error R beats
  output logic      [31:0]                   frames_in,            // frames written (all BRESP)
  output logic      [31:0]                   frames_out            // frames completely read out
);

  // ---- derived sizes (powers of two, but for NUM_TX's factor) ---------------------------
  localparam int WORD_W  = NUM_RX * 2 * DATA_W;
  localparam int UNIT_W  = (WORD_W > AXI_DATA_W) ? WORD_W : AXI_DATA_W; // on-chip entry
  localparam int WPU     = UNIT_W / WORD_W;       // words per unit
  localparam int BPU     = UNIT_W / AXI_DATA_W;   // AXI beats per unit
  localparam longint WORD_B  = longint'(WORD_W) / 64'sd8;
  localparam longint AXI_B   = longint'(AXI_DATA_W) / 64'sd8;
  localparam int S       = N_RANGE / TILE_R;      // strips per TX
  localparam longint WB_BYTES    = TILE_R * WORD_B;                 // one write burst (row)
  localparam int     WB_BEATS    = int'(WB_BYTES / AXI_B);
  localparam int     G           = (READ_ORDER == 1) ? NUM_TX : 1;  // strips per group
  localparam longint STRIP_BYTES = WB_BYTES * N_DOPPLER;
  localparam longint GROUP_BYTES = STRIP_BYTES * G;
  localparam longint GROUP_LOW   = GROUP_BYTES & -GROUP_BYTES;       // power-of-two factor
  localparam longint RB_BYTES    = (GROUP_LOW < 4096) ? GROUP_LOW : 4096; // one read burst
  localparam int     RB_BEATS    = int'(RB_BYTES / AXI_B);
  localparam int     RB_UNITS    = RB_BEATS / BPU;
  localparam int     GROUP_UNITS = int'(GROUP_BYTES * 8 / longint'(UNIT_W));
  localparam int     WB_UNITS    = int'(WB_BYTES * 8 / longint'(UNIT_W));
  localparam int     GROUP_WORDS = TILE_R * N_DOPPLER * G;
  localparam longint FRAME_BYTES = STRIP_BYTES * S * NUM_TX;
  localparam int     WBURSTS     = NUM_TX * N_DOPPLER * S;          // write bursts per frame
  localparam int     RBURSTS     = int'(FRAME_BYTES / RB_BYTES);    // read bursts per frame
  localparam int     NGROUPS     = NUM_TX * S / G;                  // groups per frame

  localparam int BS  = $clog2(S);
  localparam int BT  = (NUM_TX > 1) ? $clog2(NUM_TX) : 1;
  localparam int BD  = $clog2(N_DOPPLER);
  localparam int BRG = $clog2(N_RANGE);
  localparam int BTR = $clog2(TILE_R);
  localparam int BWPU = $clog2(WPU);
  localparam int BG  = (G > 1) ? $clog2(G) : 1;
  // counter widths (at least 1 bit)
  localparam int WBW  = (WBURSTS > 1) ? $clog2(WBURSTS) : 1;
  localparam int RBW  = (RBURSTS > 1) ? $clog2(RBURSTS) : 1;
  localparam int WBTW = (WB_BEATS > 1) ? $clog2(WB_BEATS) : 1;
  localparam int RBTW = (RB_BEATS > 1) ? $clog2(RB_BEATS) : 1;
  localparam int BPW_ = (BPU > 1) ? $clog2(BPU) : 1;
  localparam int SIW  = (NGROUPS > 1) ? $clog2(NGROUPS) : 1;
  localparam int OIW  = $clog2(GROUP_WORDS);                        // >= 1 (N_DOPPLER >= 2)
  localparam int HALF_AW   = (GROUP_UNITS > 1) ? $clog2(GROUP_UNITS) : 1;
  localparam int BUF_DEPTH = 2 << HALF_AW;        // two groups, each in 2^HALF_AW entries
  localparam int BUF_AW    = HALF_AW + 1;
  localparam int CRW       = BUF_AW + 1;
  localparam int OUTW      = $clog2(MAX_OUTSTANDING + 1);
  localparam logic [2:0] AXI_SIZE = 3'($clog2(AXI_DATA_W / 8));

  // ---- parameter checks -----------------------------------------------------------------
  if (NUM_TX < 1 || NUM_TX > 16) begin : g_bad_num_tx
    $fatal(1, "frame_store_axi (%m): NUM_TX=%0d not in 1..16", NUM_TX);
  end
  if (NUM_RX < 1 || NUM_RX > 16 || (NUM_RX & (NUM_RX - 1)) != 0) begin : g_bad_num_rx
    $fatal(1, "frame_store_axi (%m): NUM_RX=%0d must be a power of two in 1..16", NUM_RX);
  end
  if (N_RANGE < 2 || N_RANGE > 4096 || (1 << BRG) != N_RANGE) begin : g_bad_n_range
    $fatal(1, "frame_store_axi (%m): N_RANGE=%0d must be a power of two in 2..4096", N_RANGE);
  end
  if (N_DOPPLER < 2 || N_DOPPLER > 4096 || (1 << BD) != N_DOPPLER) begin : g_bad_n_doppler
    $fatal(1, "frame_store_axi (%m): N_DOPPLER=%0d must be a power of two in 2..4096",
           N_DOPPLER);
  end
  if (READ_ORDER != 0 && READ_ORDER != 1) begin : g_bad_read_order
    $fatal(1, "frame_store_axi (%m): READ_ORDER=%0d must be 0 (t, r, d) or 1 (r, t, d)",
           READ_ORDER);
  end
  if (DATA_W != 8 && DATA_W != 16 && DATA_W != 32) begin : g_bad_data_w
    $fatal(1, "frame_store_axi (%m): DATA_W=%0d must be 8, 16 or 32", DATA_W);
  end
  if (AXI_DATA_W != 128 && AXI_DATA_W != 256 && AXI_DATA_W != 512) begin : g_bad_axi_data_w
    $fatal(1, "frame_store_axi (%m): AXI_DATA_W=%0d must be 128, 256 or 512", AXI_DATA_W);
  end
  if (AXI_ADDR_W < 32 || AXI_ADDR_W > 40) begin : g_bad_axi_addr_w
    $fatal(1, "frame_store_axi (%m): AXI_ADDR_W=%0d not in 32..40", AXI_ADDR_W);
  end
  if (AXI_ID_W < 1 || AXI_ID_W > 8) begin : g_bad_axi_id_w
    $fatal(1, "frame_store_axi (%m): AXI_ID_W=%0d not in 1..8", AXI_ID_W);
  end
  if (TILE_R < 1 || TILE_R > N_RANGE || (1 << BTR) != TILE_R) begin : g_bad_tile_r
    $fatal(1, "frame_store_axi (%m): TILE_R=%0d must be a power of two in 1..N_RANGE", TILE_R);
  end
  if (WB_BYTES < AXI_B || WB_BYTES > 4096) begin : g_bad_tile_bytes
    $fatal(1, "frame_store_axi (%m): TILE_R=%0d gives %0d-byte rows, need %0d..4096 (one AXI beat to 4 KiB)",
           TILE_R, WB_BYTES, AXI_B);
  end
  if (MEM_BASE % 4096 != 0) begin : g_bad_mem_base
    $fatal(1, "frame_store_axi (%m): MEM_BASE=0x%0h is not 4 KiB aligned", MEM_BASE);
  end
  if (MEM_BASE + 2 * FRAME_BYTES > (64'd1 << AXI_ADDR_W)) begin : g_bad_mem_base_range
    $fatal(1, "frame_store_axi (%m): MEM_BASE=0x%0h + 2 frames (%0d bytes) beyond AXI_ADDR_W=%0d",
           MEM_BASE, 2 * FRAME_BYTES, AXI_ADDR_W);
  end
  if (MAX_OUTSTANDING < 1 || MAX_OUTSTANDING > 32) begin : g_bad_max_outstanding
    $fatal(1, "frame_store_axi (%m): MAX_OUTSTANDING=%0d not in 1..32", MAX_OUTSTANDING);
  end
  if (WFIFO_DEPTH < 4 || WFIFO_DEPTH > 1024 || (WFIFO_DEPTH & (WFIFO_DEPTH - 1)) != 0)
  begin : g_bad_wfifo_depth
    $fatal(1, "frame_store_axi (%m): WFIFO_DEPTH=%0d must be a power of two in 4..1024",
           WFIFO_DEPTH);
  end
  if (WFIFO_DEPTH < 2 * WB_UNITS) begin : g_bad_wfifo_bursts
    $fatal(1, "frame_store_axi (%m): WFIFO_DEPTH=%0d holds less than two %0d-entry write bursts",
           WFIFO_DEPTH, WB_UNITS);
  end

  // ---- frame bookkeeping (frame counters mod 4; differences are 0..2) --------------------
  logic [1:0] aw_f_q;   // frame of the next AW
  logic [1:0] b_f_q;    // frames with every BRESP in
  logic [1:0] ar_f_q;   // frame of the next AR
  logic [1:0] r_f_q;    // frames with every R beat in
  logic [1:0] aw_lead;
  assign aw_lead = aw_f_q - r_f_q;

  // =========================================================================================
  // Write side: s_axis -> pack words into units -> FIFO -> split units into beats -> W
  // =========================================================================================
  logic [BRG-1:0]    in_pos_q;   // range bin of the next input word
  logic              in_beat;
  logic [UNIT_W-1:0] pk_tdata, wf_tdata;
  logic              pk_tvalid, pk_tready, wf_tvalid, wf_tready;
  logic [AXI_DATA_W-1:0] wb_tdata;
  logic              wb_tvalid, wb_tready;

  assign in_beat = s_axis_tvalid && s_axis_tready;

  frame_store_gearbox #(.IN_W(WORD_W), .OUT_W(UNIT_W)) u_wpack (
    .clk, .rst,
    .s_axis_tdata(s_axis_tdata), .s_axis_tvalid(s_axis_tvalid), .s_axis_tready(s_axis_tready),
    .m_axis_tdata(pk_tdata), .m_axis_tvalid(pk_tvalid), .m_axis_tready(pk_tready)
  );

  frame_store_fifo #(.WIDTH(UNIT_W), .DEPTH(WFIFO_DEPTH)) u_wfifo (
    .clk, .rst,
    .s_axis_tdata(pk_tdata), .s_axis_tvalid(pk_tvalid), .s_axis_tready(pk_tready),
    .m_axis_tdata(wf_tdata), .m_axis_tvalid(wf_tvalid), .m_axis_tready(wf_tready)
  );

  frame_store_gearbox #(.IN_W(UNIT_W), .OUT_W(AXI_DATA_W)) u_wsplit (
    .clk, .rst,
    .s_axis_tdata(wf_tdata), .s_axis_tvalid(wf_tvalid), .s_axis_tready(wf_tready),
    .m_axis_tdata(wb_tdata), .m_axis_tvalid(wb_tvalid), .m_axis_tready(wb_tready)
  );

  // AW: one burst per (chirp, strip) in input order: index = (d*NUM_TX + t)*S + s; the row
  // goes to strip t*S + s (READ_ORDER 0) or s*NUM_TX + t (READ_ORDER 1)
  logic [WBW-1:0]  aw_idx_q;
  logic [OUTW-1:0] aw_out_q;     // AW issued, BRESP not yet in
  logic signed [WBW+1:0] w_open_q; // AWs accepted minus W bursts completed (-1..WBURSTS)
  logic [WBTW-1:0] w_beat_q;     // beat within the current W burst
  logic [WBW-1:0]  b_idx_q;
  localparam int WUW = (WB_UNITS > 1) ? $clog2(WB_UNITS) : 1;
  localparam int AVW = $clog2(WFIFO_DEPTH + 1);
  logic [WUW-1:0]  wu_idx_q;     // unit within the burst being filled into the FIFO
  logic [AVW-1:0]  avail_q;      // complete bursts in the FIFO without an AW yet
  logic            pk_hs, burst_in;
  logic            aw_hs, w_hs, w_end, b_hs, w_ok;
  logic [63:0]     aw_off;
  // digits of aw_idx_q = (d*NUM_TX + t)*S + s
  localparam int AWS_W = (BS > 0) ? BS : 1;
  localparam logic [AWS_W-1:0] AW_S_LAST = AWS_W'(S - 1);   // 0 with one strip (never counts)
  logic [AWS_W-1:0] aw_s_q;
  logic [BT-1:0]   aw_t_q;
  logic [BD-1:0]   aw_d_q;

  always_comb begin
    logic [63:0] s_, t_, d_;
    s_  = (BS > 0) ? 64'(aw_s_q) : 64'd0;
    t_  = 64'(aw_t_q);
    d_  = 64'(aw_d_q);
    aw_off = ((READ_ORDER == 1 ? (s_ * 64'(NUM_TX) + t_) : (t_ * 64'(S) + s_))
              * 64'(N_DOPPLER) + d_) * 64'(WB_BYTES)
           + (aw_f_q[0] ? 64'(FRAME_BYTES) : 64'd0);
  end

  // AW only for a burst whose data all waits in the FIFO (W then follows at full rate) and
  // whose frame area has been read back
  assign pk_hs    = pk_tvalid && pk_tready;
  assign burst_in = pk_hs && (wu_idx_q == WUW'(WB_UNITS - 1));
  assign m_axi_mem_awvalid = !rst && (avail_q != '0) && (aw_lead != 2'd2)
                             && (aw_out_q < OUTW'(MAX_OUTSTANDING));
  assign m_axi_mem_awaddr  = AXI_ADDR_W'(MEM_BASE + aw_off);
  assign m_axi_mem_awid    = '0;
  assign m_axi_mem_awlen   = 8'(WB_BEATS - 1);
  assign m_axi_mem_awsize  = AXI_SIZE;
  assign m_axi_mem_awburst = 2'b01;      // INCR
  assign m_axi_mem_awlock  = 1'b0;
  assign m_axi_mem_awcache = 4'b0011;    // normal non-cacheable bufferable
  assign m_axi_mem_awprot  = 3'b000;
  assign aw_hs = m_axi_mem_awvalid && m_axi_mem_awready;

  // W of a burst may start as soon as its AW is presented (AXI4: the master never waits for
  // AWREADY before WVALID; a slave may wait for WVALID before AWREADY). With no accepted AW
  // still owed data, the data at the FIFO head belongs to the AW being presented; a burst
  // whose W finished before its AW was accepted (w_open_q = -1) lets nothing more through.
  assign w_ok              = (w_open_q > 0) || (w_open_q == 0 && m_axi_mem_awvalid);
  assign m_axi_mem_wvalid  = wb_tvalid && w_ok;
  assign wb_tready         = m_axi_mem_wready && w_ok;
  assign m_axi_mem_wdata   = wb_tdata;
  assign m_axi_mem_wstrb   = '1;
  assign m_axi_mem_wlast   = (w_beat_q == WBTW'(WB_BEATS - 1));
  assign w_hs  = m_axi_mem_wvalid && m_axi_mem_wready;
  assign w_end = w_hs && m_axi_mem_wlast;

  assign m_axi_mem_bready = !rst;
  assign b_hs = m_axi_mem_bvalid && m_axi_mem_bready;

  // =========================================================================================
  // Read side: AR linear over the frame area -> R beats -> units -> two-group buffer
  // =========================================================================================
  logic [RBW-1:0]  ar_idx_q;
  logic [OUTW-1:0] ar_out_q;     // AR issued, last R beat not yet in
  logic [CRW-1:0]  credit_q;     // free buffer units not yet reserved by an AR
  logic [RBTW-1:0] r_beat_q;
  logic [RBW-1:0]  r_burst_q;
  logic [BPW_-1:0] r_part_q;     // beat within the current unit
  logic [UNIT_W-1:0] r_acc_q;
  logic [BUF_AW-1:0] buf_wptr_q;   // {half, unit within the group}
  logic [1:0]      recv_sc_q;    // strips completely in the buffer (mod 4)
  logic            ar_hs, r_hs, r_end, r_unit, r_last_exp;
  logic [UNIT_W-1:0] r_unit_data;

  assign m_axi_mem_arvalid = !rst && (ar_f_q != b_f_q) && (ar_out_q < OUTW'(MAX_OUTSTANDING))
                             && (credit_q >= CRW'(RB_UNITS));
  assign m_axi_mem_araddr  = AXI_ADDR_W'(MEM_BASE + 64'(ar_idx_q) * 64'(RB_BYTES)
                             + (ar_f_q[0] ? 64'(FRAME_BYTES) : 64'd0));
  assign m_axi_mem_arid    = '0;
  assign m_axi_mem_arlen   = 8'(RB_BEATS - 1);
  assign m_axi_mem_arsize  = AXI_SIZE;
  assign m_axi_mem_arburst = 2'b01;
  assign m_axi_mem_arlock  = 1'b0;
  assign m_axi_mem_arcache = 4'b0011;
  assign m_axi_mem_arprot  = 3'b000;
  assign ar_hs = m_axi_mem_arvalid && m_axi_mem_arready;

  // every AR has its buffer space reserved: R is always accepted
  assign m_axi_mem_rready = !rst;
  assign r_hs       = m_axi_mem_rvalid && m_axi_mem_rready;
  assign r_last_exp = (r_beat_q == RBTW'(RB_BEATS - 1));
  assign r_end      = r_hs && r_last_exp;

  if (BPU > 1) begin : g_r_pack
    assign r_unit      = r_hs && (r_part_q == BPW_'(BPU - 1));
    always_comb begin
      r_unit_data = r_acc_q;
      r_unit_data[(BPU-1)*AXI_DATA_W +: AXI_DATA_W] = m_axi_mem_rdata;
    end
    always_ff @(posedge clk) begin
      if (r_hs) r_acc_q[r_part_q*AXI_DATA_W +: AXI_DATA_W] <= m_axi_mem_rdata;
    end
  end else begin : g_r_direct
    assign r_unit      = r_hs;
    assign r_unit_data = m_axi_mem_rdata;
    always_ff @(posedge clk) r_acc_q <= '0;
  end

  // ---- group buffer ----------------------------------------------------------------------
  logic              ram_rd_en;
  logic [BUF_AW-1:0] ram_rd_addr;
  logic [UNIT_W-1:0] ram_rd_data;

  buf_sdp_ram #(.WIDTH(UNIT_W), .DEPTH(BUF_DEPTH), .OUT_REG(1'b1)) u_strip_buf (
    .clk     (clk),
    .wr_en   (r_unit),
    .wr_addr (buf_wptr_q),
    .wr_data (r_unit_data),
    .rd_en   (ram_rd_en),
    .rd_addr (ram_rd_addr),
    .rd_data (ram_rd_data)
  );

  // =========================================================================================
  // Output: group by group, for r in the group, for t in the group (order 1), for d:
  // word (t*N_DOPPLER + d)*TILE_R + r of the group (order 0: t = 0)
  // =========================================================================================
  logic [OIW-1:0] o_idx_q;       // (r*G + t)*N_DOPPLER + d within the group
  logic [BG-1:0]  o_t_q;         // its digits t and r (d = o_idx_q mod N_DOPPLER)
  logic [BTR > 0 ? BTR - 1 : 0:0] o_r_q;
  logic [SIW-1:0] o_strip_q;     // group within the frame
  logic [1:0]     out_sc_q;      // groups completely read out (mod 4)
  logic           can_issue, o_issue, o_strip_end;
  logic [OIW-1:0] o_word;        // word index inside the group (memory order)
  logic           p_last_q, p_sof_q, p2_last_q, p2_sof_q;   // read issued 1 / 2 clocks ago
  logic [(BWPU > 0 ? BWPU : 1)-1:0] p_sel_q, p2_sel_q;

  always_comb begin
    logic [31:0] d_, t_, r_;
    d_  = 32'(o_idx_q) & 32'(N_DOPPLER - 1);
    t_  = (G > 1) ? 32'(o_t_q) : 32'd0;
    r_  = (BTR > 0) ? 32'(o_r_q) : 32'd0;
    o_word = OIW'((t_ * 32'(N_DOPPLER) + d_) * 32'(TILE_R) + r_);
  end

  assign o_issue     = (out_sc_q != recv_sc_q) && can_issue;
  assign o_strip_end = (o_idx_q == OIW'(GROUP_WORDS - 1));
  assign ram_rd_en   = o_issue;
  assign ram_rd_addr = {out_sc_q[0], (BUF_AW-1)'(o_word >> BWPU)};

  always_ff @(posedge clk) begin
    p_last_q <= ((o_idx_q & OIW'(N_DOPPLER - 1)) == OIW'(N_DOPPLER - 1));
    p_sof_q  <= (o_idx_q == '0) && (o_strip_q == '0);
    p_sel_q  <= (BWPU > 0) ? o_word[(BWPU > 0 ? BWPU : 1)-1:0] : '0;
    p2_last_q <= p_last_q;
    p2_sof_q  <= p_sof_q;
    p2_sel_q  <= p_sel_q;
  end

  logic [WORD_W-1:0] o_word_data;
  if (WPU > 1) begin : g_o_select
    assign o_word_data = ram_rd_data[p2_sel_q*WORD_W +: WORD_W];
  end else begin : g_o_whole
    assign o_word_data = ram_rd_data[WORD_W-1:0];
    /* verilator lint_off UNUSEDSIGNAL */
    logic unused_sel;
    assign unused_sel = ^p2_sel_q;
    /* verilator lint_on UNUSEDSIGNAL */
  end

  logic [WORD_W+1:0] fifo_tdata;
  buf_out_fifo #(.WIDTH(WORD_W + 2), .DEPTH(4), .LATENCY(2)) u_out (
    .clk           (clk),
    .rst           (rst),
    .can_issue     (can_issue),
    .issue         (o_issue),
    .in_data       ({p2_sof_q, p2_last_q, o_word_data}),
    .m_axis_tdata  (fifo_tdata),
    .m_axis_tvalid (m_axis_tvalid),
    .m_axis_tready (m_axis_tready)
  );
  assign m_axis_tdata    = fifo_tdata[WORD_W-1:0];
  assign m_axis_tlast    = fifo_tdata[WORD_W];
  assign m_axis_tuser[0] = fifo_tdata[WORD_W+1];

  // =========================================================================================
  // State
  // =========================================================================================
  logic        framing_q, mem_err_q;
  logic [31:0] framing_cnt_q, mem_err_cnt_q, frames_in_q, frames_out_q;
  logic        b_err, r_err;
  logic [1:0]  mem_err_events;
  assign b_err = b_hs && (m_axi_mem_bresp != 2'b00);
  assign r_err = r_hs && ((m_axi_mem_rresp != 2'b00) || (m_axi_mem_rlast != r_last_exp));
  assign mem_err_events = 2'(b_err) + 2'(r_err);

  always_ff @(posedge clk) begin
    if (rst) begin
      in_pos_q      <= '0;
      framing_q     <= 1'b0;
      framing_cnt_q <= '0;
      aw_f_q        <= '0;
      b_f_q         <= '0;
      ar_f_q        <= '0;
      r_f_q         <= '0;
      aw_idx_q      <= '0;
      aw_s_q        <= '0;
      aw_t_q        <= '0;
      aw_d_q        <= '0;
      aw_out_q      <= '0;
      w_open_q      <= '0;
      w_beat_q      <= '0;
      b_idx_q       <= '0;
      wu_idx_q      <= '0;
      avail_q       <= '0;
      ar_idx_q      <= '0;
      ar_out_q      <= '0;
      credit_q      <= CRW'(2 * GROUP_UNITS);
      r_beat_q      <= '0;
      r_burst_q     <= '0;
      r_part_q      <= '0;
      buf_wptr_q    <= '0;
      recv_sc_q     <= '0;
      o_idx_q       <= '0;
      o_t_q         <= '0;
      o_r_q         <= '0;
      o_strip_q     <= '0;
      out_sc_q      <= '0;
      mem_err_q     <= 1'b0;
      mem_err_cnt_q <= '0;
      frames_in_q   <= '0;
      frames_out_q  <= '0;
    end else begin
      // ---- input framing (data is placed by count; a misplaced TLAST is only reported)
      if (in_beat) begin
        in_pos_q <= in_pos_q + 1'b1;
        if (s_axis_tlast != (in_pos_q == '1)) begin
          framing_q <= 1'b1;
          if (framing_cnt_q != '1) framing_cnt_q <= framing_cnt_q + 1'b1;
        end
      end

      // ---- AW / W / B
      if (pk_hs) wu_idx_q <= (wu_idx_q == WUW'(WB_UNITS - 1)) ? '0 : wu_idx_q + 1'b1;
      avail_q <= avail_q + AVW'(burst_in) - AVW'(aw_hs);
      if (aw_hs) begin
        aw_idx_q <= aw_idx_q + 1'b1;
        if (aw_idx_q == WBW'(WBURSTS - 1)) begin
          aw_idx_q <= '0;
          aw_f_q   <= aw_f_q + 1'b1;
        end
        if (aw_s_q == AW_S_LAST) begin
          aw_t_q <= (aw_t_q == BT'(NUM_TX - 1)) ? '0 : aw_t_q + 1'b1;
          if (aw_t_q == BT'(NUM_TX - 1)) aw_d_q <= aw_d_q + 1'b1;
        end
        if (BS > 0) aw_s_q <= aw_s_q + 1'b1;
      end
      aw_out_q <= aw_out_q + OUTW'(aw_hs) - OUTW'(b_hs);
      w_open_q <= w_open_q + $signed((WBW+2)'(aw_hs)) - $signed((WBW+2)'(w_end));
      if (w_hs) w_beat_q <= m_axi_mem_wlast ? '0 : w_beat_q + 1'b1;
      if (b_hs) begin
        b_idx_q <= b_idx_q + 1'b1;
        if (b_idx_q == WBW'(WBURSTS - 1)) begin
          b_idx_q     <= '0;
          b_f_q       <= b_f_q + 1'b1;
          frames_in_q <= frames_in_q + 1'b1;
        end
      end

      // ---- AR / R
      if (ar_hs) begin
        ar_idx_q <= (ar_idx_q == RBW'(RBURSTS - 1)) ? '0 : ar_idx_q + 1'b1;
        if (ar_idx_q == RBW'(RBURSTS - 1)) ar_f_q <= ar_f_q + 1'b1;
      end
      ar_out_q <= ar_out_q + OUTW'(ar_hs) - OUTW'(r_end);
      credit_q <= credit_q - (ar_hs ? CRW'(RB_UNITS) : '0)
                           + ((o_issue && o_strip_end) ? CRW'(GROUP_UNITS) : '0);
      if (r_hs) begin
        r_beat_q <= r_last_exp ? '0 : r_beat_q + 1'b1;
        if (BPU > 1) r_part_q <= r_part_q + 1'b1;
      end
      if (r_end) begin
        r_burst_q <= (r_burst_q == RBW'(RBURSTS - 1)) ? '0 : r_burst_q + 1'b1;
        if (r_burst_q == RBW'(RBURSTS - 1)) r_f_q <= r_f_q + 1'b1;
      end
      if (r_unit) begin
        buf_wptr_q <= buf_wptr_q + 1'b1;
        if (buf_wptr_q[BUF_AW-2:0] == (BUF_AW-1)'(GROUP_UNITS - 1)) begin
          buf_wptr_q <= {~buf_wptr_q[BUF_AW-1], (BUF_AW-1)'(0)};
          recv_sc_q  <= recv_sc_q + 1'b1;
        end
      end

      // ---- output
      if (o_issue) begin
        o_idx_q <= o_strip_end ? '0 : o_idx_q + 1'b1;
        if ((o_idx_q & OIW'(N_DOPPLER - 1)) == OIW'(N_DOPPLER - 1)) begin
          o_t_q <= (o_t_q == BG'(G - 1)) ? '0 : o_t_q + 1'b1;
          if (o_t_q == BG'(G - 1)) o_r_q <= o_r_q + 1'b1;
        end
        if (o_strip_end) begin
          out_sc_q  <= out_sc_q + 1'b1;
          o_strip_q <= (o_strip_q == SIW'(NGROUPS - 1)) ? '0 : o_strip_q + 1'b1;
          if (o_strip_q == SIW'(NGROUPS - 1)) frames_out_q <= frames_out_q + 1'b1;
        end
      end

      // ---- memory errors: counted, never waited for
      if (b_err || r_err) mem_err_q <= 1'b1;
      if (mem_err_events != 2'd0)
        mem_err_cnt_q <= (mem_err_cnt_q > 32'hFFFF_FFFD) ? '1
                                                         : mem_err_cnt_q + 32'(mem_err_events);
    end
  end

  assign status_framing_error = framing_q;
  assign framing_error_count  = framing_cnt_q;
  assign status_mem_error     = mem_err_q;
  assign mem_error_count      = mem_err_cnt_q;
  assign frames_in            = frames_in_q;
  assign frames_out           = frames_out_q;

  // IDs are not checked: the store issues ID 0 only and needs no reordering.
  /* verilator lint_off UNUSEDSIGNAL */
  logic unused_ok;
  assign unused_ok = ^{m_axi_mem_bid, m_axi_mem_rid, r_acc_q};
  /* verilator lint_on UNUSEDSIGNAL */

  // AXI4-Stream / AXI4 handshake rules on every port and channel (rtl/common/axis_checker.sv:
  // VALID held until READY, payload stable while stalled)
  axis_checker #(.PAYLOAD_W(WORD_W + 1), .ASSUME(1'b1)) u_chk_s_axis (
    .clk, .rst, .tvalid(s_axis_tvalid), .tready(s_axis_tready),
    .payload({s_axis_tlast, s_axis_tdata}));
  axis_checker #(.PAYLOAD_W(WORD_W + 2)) u_chk_m_axis (
    .clk, .rst, .tvalid(m_axis_tvalid), .tready(m_axis_tready),
    .payload({m_axis_tuser, m_axis_tlast, m_axis_tdata}));
  axis_checker #(.PAYLOAD_W(AXI_ADDR_W + 8)) u_chk_aw (
    .clk, .rst, .tvalid(m_axi_mem_awvalid), .tready(m_axi_mem_awready),
    .payload({m_axi_mem_awlen, m_axi_mem_awaddr}));
  axis_checker #(.PAYLOAD_W(AXI_DATA_W + 1)) u_chk_w (
    .clk, .rst, .tvalid(m_axi_mem_wvalid), .tready(m_axi_mem_wready),
    .payload({m_axi_mem_wlast, m_axi_mem_wdata}));
  axis_checker #(.PAYLOAD_W(AXI_ID_W + 2), .ASSUME(1'b1)) u_chk_b (
    .clk, .rst, .tvalid(m_axi_mem_bvalid), .tready(m_axi_mem_bready),
    .payload({m_axi_mem_bid, m_axi_mem_bresp}));
  axis_checker #(.PAYLOAD_W(AXI_ADDR_W + 8)) u_chk_ar (
    .clk, .rst, .tvalid(m_axi_mem_arvalid), .tready(m_axi_mem_arready),
    .payload({m_axi_mem_arlen, m_axi_mem_araddr}));
  axis_checker #(.PAYLOAD_W(AXI_ID_W + AXI_DATA_W + 3), .ASSUME(1'b1)) u_chk_r (
    .clk, .rst, .tvalid(m_axi_mem_rvalid), .tready(m_axi_mem_rready),
    .payload({m_axi_mem_rid, m_axi_mem_rresp, m_axi_mem_rlast, m_axi_mem_rdata}));

`ifndef SYNTHESIS
  // block invariants: AXI4 4 KiB rule, group buffer never over-reserved
  always_ff @(posedge clk) begin
    if (!rst) begin
      if (m_axi_mem_awvalid)
        assert ({1'b0, m_axi_mem_awaddr[11:0]} + 13'(WB_BYTES) <= 13'h1000)
          else $error("frame_store_axi: write burst crosses 4 KiB");
      if (m_axi_mem_arvalid)
        assert ({1'b0, m_axi_mem_araddr[11:0]} + 13'(RB_BYTES) <= 13'h1000)
          else $error("frame_store_axi: read burst crosses 4 KiB");
      if (r_unit) assert (credit_q <= CRW'(2 * GROUP_UNITS))
        else $error("frame_store_axi: group buffer over-reserved");
    end
  end
`endif

endmodule

`default_nettype wire
