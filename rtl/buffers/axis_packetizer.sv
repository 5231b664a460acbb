// SPDX-License-Identifier: Apache-2.0
// DMA packetizer: a ring of packet banks (double buffer by default) that decouples the
// Doppler FFT from a stalling DMA sink, cuts each frame into TLAST-closed packets, prepends
// a header word to each packet and appends a CRC word (CRC-32 of header and payload).
//
// Packet and header format: docs/buffers.md and model/axis_packetizer.py (the host shares
// it); the CRC: model/packet_crc.py, which generates packet_crc32.sv.
// Frame boundaries come from counting FRAME_WORDS input words after reset; s_axis_tlast is
// only checked (every TLAST_PERIOD words) and a mismatch raises the framing error flag.
// Packet length: cfg_packet_words (a run-time setting, PACKET_WORDS_MIN..PACKET_WORDS, see
// below) taken with a frame's first word and held for the frame. The packets per frame the
// header states come from a sequential divider (13 clocks) that follows the setting while
// no word of a frame has been taken; only when the length changed fewer clocks than that
// before a frame's first packet closes does the input wait for it (INPUT_BACKPRESSURE = 1;
// with 0 the length must stay PACKET_WORDS).
// Store and forward: a packet is sent only once it is complete in its bank, so its header
// can state its exact length and whether words were dropped from it.
`default_nettype none

module axis_packetizer #(
  // Receive lanes per word (one 32-bit {Q,I} sample each), 1..64.
  parameter int NUM_RX = 4,
  // Bits of I and of Q; the DMA format is 32-bit {Q,I} lanes, so only 16 is legal.
  parameter int DATA_W = 16,
  // Payload words per packet at most (the last packet of a frame may be shorter), 2..65535;
  // the run-time length cfg_packet_words may be shorter.
  parameter int PACKET_WORDS = 256,
  // Payload words per frame, 1..2^30; at most 4096 packets per frame (12-bit sequence).
  parameter int FRAME_WORDS = 16384,
  // Packet banks in the output buffer ring, power of two, 2..16. 2 is the paper's double
  // buffer; more banks absorb longer DMA stalls and short frame-final packets when the
  // input cannot be stalled.
  parameter int NUM_BANKS = 2,
  // 1: one header word before every packet's payload and one CRC word after it (lane 0 =
  //    CRC-32 of the header and payload wire bytes, other lanes 0); 0: payload only.
  parameter bit HEADER = 1'b1,
  // 1: s_axis_tready deasserts while the bank to write is full (no loss; a stalled DMA
  //    then stalls the pipeline back to the ADC ping-pong, which flags the loss there);
  // 0: s_axis_tready is always 1 and a word that finds all banks full is dropped,
  //    counted and flagged (for producers that cannot be stalled).
  parameter bit INPUT_BACKPRESSURE = 1'b1,
  // Expected s_axis_tlast period in words (e.g. N_DOPPLER), must divide FRAME_WORDS;
  // 0 ignores s_axis_tlast.
  parameter int TLAST_PERIOD = 0
) (
  input  wire logic                     clk,
  input  wire logic                     rst,
  // Payload words per packet for the frames from the next one on, PACKET_WORDS_MIN ..
  // PACKET_WORDS (PACKET_WORDS_MIN = max(2, ceil(FRAME_WORDS / 4096))), sampled with a
  // frame's first word; tie to PACKET_WORDS for a fixed length
  input  wire logic [15:0]              cfg_packet_words,
  // Input stream (Doppler FFT output, payload order)
  input  wire logic [NUM_RX*32-1:0]     s_axis_tdata,
  input  wire logic                     s_axis_tvalid,
  output logic                          s_axis_tready,
  input  wire logic                     s_axis_tlast,
  // 1 on words of a frame damaged upstream (zero-filled chirps): sets DAMAGED in the
  // header of every packet holding such a word (tie to 0 when unused)
  input  wire logic [0:0]               s_axis_tuser,
  // DMA stream: [header payload CRC] or payload only (HEADER=0), TLAST on the last word of
  // every packet
  output logic      [NUM_RX*32-1:0]     m_axis_tdata,
  output logic                          m_axis_tvalid,
  input  wire logic                     m_axis_tready,
  output logic                          m_axis_tlast,
  // Status (cleared only by rst)
  output logic                          status_overflow,       // sticky: a word was dropped
  output logic                          status_framing_error,  // sticky: s_axis_tlast misplaced
  output logic      [31:0]              drop_count,            // words dropped (saturating)
  output logic      [31:0]              framing_error_count,   // misplaced/missing tlasts
  output logic      [31:0]              frame_count,           // input frames completed
  output logic      [31:0]              packet_count           // packets sent (incl. header)
);

  // ---------------------------------------------------------------------------------------
  // Derived sizes
  localparam int WORD_W    = NUM_RX * 32;
  localparam int NPKT      = (FRAME_WORDS + PACKET_WORDS - 1) / PACKET_WORDS;
  /* verilator lint_off UNUSEDPARAM */ // (the formal properties' packet plan)
  localparam int LAST_LEN  = FRAME_WORDS - (NPKT - 1) * PACKET_WORDS;  // words, last packet
  /* verilator lint_on UNUSEDPARAM */
  localparam int POS_W     = $clog2(PACKET_WORDS);
  localparam int BANK_W    = $clog2(NUM_BANKS);
  localparam int LEN_W     = $clog2(PACKET_WORDS + 1);
  localparam int SEQ_W     = 12;
  localparam int TLP       = (TLAST_PERIOD > 0) ? TLAST_PERIOD : 1;
  localparam int TLP_W     = $clog2(TLP + 1);
  localparam int FWC_W     = $clog2(FRAME_WORDS + 1);
  localparam int NP_W      = 13;                                       // packets per frame
  localparam int PW_MIN    = ((FRAME_WORDS + 4095) / 4096 > 2)          // shortest packet
                             ? (FRAME_WORDS + 4095) / 4096 : 2;
  localparam logic [7:0] MAGIC = 8'hA5;

  // Parameter checks: stop elaboration on illegal values.
  if (NUM_RX < 1 || NUM_RX > 64) begin : g_bad_num_rx
    $fatal(1, "%m: NUM_RX=%0d not in 1..64", NUM_RX);
  end
  if (DATA_W != 16) begin : g_bad_data_w
    $fatal(1, "%m: DATA_W=%0d, only 16 is legal", DATA_W);
  end
  if (PACKET_WORDS < 2 || PACKET_WORDS > 65535) begin : g_bad_packet_words
    $fatal(1, "%m: PACKET_WORDS=%0d not in 2..65535", PACKET_WORDS);
  end
  if (FRAME_WORDS < 1 || FRAME_WORDS > (1 << 30)) begin : g_bad_frame_words
    $fatal(1, "%m: FRAME_WORDS=%0d not in 1..2^30", FRAME_WORDS);
  end
  if (NPKT > 4096) begin : g_bad_frame_packets
    $fatal(1, "%m: FRAME_WORDS/PACKET_WORDS gives %0d > 4096 packets per frame",
           NPKT);
  end
  if (NUM_BANKS < 2 || NUM_BANKS > 16 || (1 << BANK_W) != NUM_BANKS) begin : g_bad_num_banks
    $fatal(1, "%m: NUM_BANKS=%0d must be a power of two in 2..16", NUM_BANKS);
  end
  if (TLAST_PERIOD < 0 || (TLAST_PERIOD > 0 && (FRAME_WORDS % TLAST_PERIOD) != 0))
  begin : g_bad_tlast_period
    $fatal(1, "%m: TLAST_PERIOD=%0d must be 0 or divide FRAME_WORDS", TLAST_PERIOD);
  end

  // ---------------------------------------------------------------------------------------
  // Packet memory: NUM_BANKS banks of 2^POS_W >= PACKET_WORDS words, address {bank, offset}
  logic              ram_wr_en, ram_rd_en;
  logic [BANK_W+POS_W-1:0] ram_wr_addr, ram_rd_addr;
  logic [WORD_W-1:0] ram_rd_data;

  buf_sdp_ram #(.WIDTH(WORD_W), .DEPTH(NUM_BANKS << POS_W), .OUT_REG(1'b1)) u_ram (
    .clk     (clk),
    .wr_en   (ram_wr_en),
    .wr_addr (ram_wr_addr),
    .wr_data (s_axis_tdata),
    .rd_en   (ram_rd_en),
    .rd_addr (ram_rd_addr),
    .rd_data (ram_rd_data)
  );

  // Per-bank packet descriptor, written by the input side when the packet is complete.
  typedef struct packed {
    logic [LEN_W-1:0] len;       // payload words stored
    logic [LEN_W-1:0] last_idx;  // len - 1, the packet's last payload index (stored so the
                                 // read side's end test is an equality, no subtractor)
    logic [LEN_W-1:0] drops;     // payload words dropped
    logic [SEQ_W-1:0] seq;       // packet number within the frame
    logic [NP_W-1:0]  npkt;      // packets of its frame
    logic [31:0]      frame;     // frame id (frames since reset)
    logic             last;      // packet ends its frame
    logic             ovf;       // status_overflow when the packet closed
    logic             framing;   // status_framing_error when the packet closed
    logic             damaged;   // a word of the packet was marked damaged upstream
  } desc_t;

  // (plain vectors: Yosys mis-reads an unpacked array of packed structs, formal/README)
  localparam int DESC_W = 3 * LEN_W + SEQ_W + NP_W + 32 + 4;  // $bits(desc_t)
  logic [DESC_W-1:0] desc_q [NUM_BANKS];
  logic [NUM_BANKS-1:0] full_q;            // bank holds a complete packet not yet fully read

  // ---------------------------------------------------------------------------------------
  // Input side
  logic [BANK_W-1:0] wr_bank_q;
  logic [POS_W-1:0] pos_q;       // input word position within the packet (dropped words count)
  logic [LEN_W-1:0] wr_cnt_q;    // words stored in the open packet
  logic [LEN_W-1:0] wr_drop_q;   // words dropped from the open packet
  logic             wr_dmg_q;    // a word of the open packet was marked damaged
  logic [SEQ_W-1:0] seq_q;
  logic [FWC_W-1:0] fw_q;        // input word position within the frame
  logic [LEN_W-1:0] pw_q, pw;    // the frame's packet length (pw: also for its first word)
  // Look-ahead flags, each updated with fw_q/pos_q/pw_q (timing: no counter compare ahead
  // of the packet end): fw_zero_q = (fw_q == 0), frame_end_q = (fw_q == FRAME_WORDS - 1),
  // pos_hit_q = (pos_q == pw_q - 1) (the packet's last position; used from its second word)
  logic             fw_zero_q, frame_end_q, pos_hit_q, pos_hit_next;
  logic [31:0]      frame_q;
  logic [TLP_W-1:0] tl_pos_q;
  logic             ovf_q, framing_q;
  logic [31:0]      drop_cnt_q, framing_cnt_q, frame_cnt_q, packet_cnt_q;

  logic             beat, space, store, frame_end, pkt_end, tlast_bad, tlast_err, npkt_ok;
  // next state of the registers s_axis_tready depends on (tready_q, after the output side)
  logic [NUM_BANKS-1:0] full_d;
  logic [BANK_W-1:0] wr_bank_d;
  logic             fw_zero_d, frame_end_d, pos_hit_d, dv_busy_d, tready_q;
  logic             desc_we;   // the closing word's descriptor is written
  logic [LEN_W-1:0] cnt_next, drop_next;

  assign pw            = fw_zero_q ? LEN_W'(cfg_packet_words) : pw_q;
  assign space         = !full_q[wr_bank_q];
  assign beat          = s_axis_tvalid && s_axis_tready;
  assign store         = beat && space;
  assign frame_end     = frame_end_q;
  // (a frame's first word is at position 0: a packet end there only with the frame's end,
  // the length being at least PW_MIN >= 2, asserted below)
  function automatic logic pkt_end_of(input logic fz, input logic hit, input logic fe);
    pkt_end_of = (!fz && hit) || fe;
  endfunction
  assign pkt_end       = pkt_end_of(fw_zero_q, pos_hit_q, frame_end);
  // pos_hit_q after this beat: position 0 (packet end; lengths are >= 2) or pos_q + 1
  // against the length pw
  assign pos_hit_next  = !pkt_end && (LEN_W'(POS_W'(pos_q + 1'b1)) + 1'b1 == pw);

  // s_axis_tready: space in the bank to write, and a packet closes only once its frame's
  // packet count is known (npkt_ok). Past a frame's first word npkt_ok is !dv_busy_q
  // (dv_op_q == pw_q there, asserted below); at the first word no packet closes unless the
  // frame is one word long. So from the first word on TREADY is a function of registers,
  // ready_of(...), and tready_q takes it from their next state (timing, docs/synth.md note
  // 26: the decision is a register, not a LUT tree the slice in front of the input waits on).
  // A frame of one word closes its packet at the first word, which compares the live
  // setting: there TREADY stays combinational.
  assign cnt_next      = wr_cnt_q + LEN_W'(store);
  assign drop_next     = wr_drop_q + LEN_W'(beat && !space);
  assign tlast_bad     = (TLAST_PERIOD > 0) &&
                         (s_axis_tlast != (tl_pos_q == TLP_W'(TLP - 1)));
  assign tlast_err     = beat && tlast_bad;
  assign desc_we       = beat && pkt_end && (wr_cnt_q != '0 || store);

  assign ram_wr_en   = store;
  assign ram_wr_addr = {wr_bank_q, wr_cnt_q[POS_W-1:0]};

  // Packets per frame, ceil(FRAME_WORDS / pw), by long division (quotient bits 12..0, one a
  // clock), restarted whenever pw changes; at reset the count of PACKET_WORDS.
  logic [LEN_W-1:0] dv_op_q;
  logic [31:0]      dv_rem_q, dv_div_q;
  logic [NP_W-1:0]  dv_np_q;
  logic [3:0]       dv_i_q;
  logic             dv_busy_q, dv_ge;
  assign dv_ge   = (dv_rem_q >= dv_div_q);
  // (dv_op_q == pw): past a frame's first word dv_op_q equals pw_q (the divider takes pw
  // every clock, and pw_q changes only at a first word, to that clock's pw; asserted below),
  // so only the first word compares, against the live setting (timing: no compare of pw_q
  // ahead of s_axis_tready)
  assign npkt_ok = !dv_busy_q && (!fw_zero_q || dv_op_q == LEN_W'(cfg_packet_words));
  assign dv_busy_d = (dv_op_q != pw) || (dv_busy_q && dv_i_q != '0);
  always_ff @(posedge clk) begin
    if (rst) begin
      dv_op_q   <= LEN_W'(PACKET_WORDS);
      dv_np_q   <= NP_W'(NPKT);
      dv_busy_q <= 1'b0;
      dv_rem_q  <= '0;
      dv_div_q  <= '0;
      dv_i_q    <= '0;
    end else begin
      dv_busy_q <= dv_busy_d;
      if (dv_op_q != pw) begin
        dv_op_q   <= pw;
        dv_rem_q  <= 32'(FRAME_WORDS) + 32'(pw) - 32'd1;
        dv_div_q  <= 32'(pw) << (NP_W - 1);
        dv_np_q   <= '0;
        dv_i_q    <= 4'(NP_W - 1);
      end else if (dv_busy_q) begin
        if (dv_ge) dv_rem_q <= dv_rem_q - dv_div_q;
        dv_np_q   <= {dv_np_q[NP_W-2:0], dv_ge};
        dv_div_q  <= dv_div_q >> 1;
        dv_i_q    <= dv_i_q - 1'b1;
      end
    end
  end

  // ---------------------------------------------------------------------------------------
  // Output side: header (if any), the payload of bank rd_bank_q, then (with the header) the
  // CRC word. The bank is released after its last payload read; the CRC word is issued the
  // next clock from crc_q, which by the time it enters the FIFO has taken in every word of
  // the packet (a word enters the FIFO two clocks after its issue: the RAM's read and output
  // registers; the header word and the sideband wait as long).
  logic [BANK_W-1:0] rd_bank_q;
  logic [POS_W-1:0] rd_idx_q;
  logic             hdr_sent_q;
  logic             crc_due_q;           // payload issued, the CRC word comes next
  logic             can_issue, issue, issue_hdr, issue_data, issue_crc, rd_last;
  logic             p_hdr_q, p_data_q, p_crc_q, p_last_q;  // sideband of last clock's issue
  logic             p2_hdr_q, p2_data_q, p2_crc_q, p2_last_q;   // ... and the clock before
  logic [WORD_W-1:0] hdr_word, p_hdr_word_q, p2_hdr_word_q, push_word;
  logic [31:0]      crc_q, crc_next;     // CRC-32 state (not inverted) of the packet so far
  logic [31:0]      crc_sent;            // the CRC word's lane 0: the final state inverted
  desc_t            rd_desc;

  assign rd_desc    = desc_q[rd_bank_q];
  assign issue      = (full_q[rd_bank_q] || crc_due_q) && can_issue;
  assign issue_crc  = issue && crc_due_q;
  assign issue_hdr  = issue && !crc_due_q && HEADER && !hdr_sent_q;
  assign issue_data = issue && !crc_due_q && !issue_hdr;
  assign rd_last    = (LEN_W'(rd_idx_q) == rd_desc.last_idx);
  assign ram_rd_en   = issue_data;
  assign ram_rd_addr = {rd_bank_q, rd_idx_q};

  // Header word (docs/buffers.md): lane 0 = {MAGIC, frame[7:0], seq[11:0], flags[3:0]},
  // flags = {framing, overflow, drop, last}; lane 1 = {dropped[15:0], length[15:0]};
  // lane 2 = frame[31:0]; lane 3 = {damaged, packets per frame[14:0], seq[15:0]}; others 0.
  localparam int HDR_W = (WORD_W > 128) ? WORD_W : 128;
  // Extension lanes beyond NUM_RX are cut off (unused when NUM_RX < 4).
  /* verilator lint_off UNUSEDSIGNAL */
  logic [HDR_W-1:0] hdr_full;
  /* verilator lint_on UNUSEDSIGNAL */
  always_comb begin
    hdr_full = '0;
    hdr_full[31:0]  = {MAGIC, rd_desc.frame[7:0], rd_desc.seq,
                       rd_desc.framing, rd_desc.ovf, (rd_desc.drops != '0), rd_desc.last};
    hdr_full[63:32] = {16'(rd_desc.drops), 16'(rd_desc.len)};
    hdr_full[95:64] = rd_desc.frame;
    hdr_full[127:96] = {rd_desc.damaged, 15'(rd_desc.npkt), 16'(rd_desc.seq)};
  end
  assign hdr_word = hdr_full[WORD_W-1:0];

  // CRC-32 at line rate: one word per clock, the header word starting from all ones
  assign push_word = p2_hdr_q ? p2_hdr_word_q : ram_rd_data;
  assign crc_sent  = ~crc_q;
  packet_crc32 #(.LANES(NUM_RX)) u_crc (
    .crc_in  (p2_hdr_q ? 32'hFFFF_FFFF : crc_q),
    .data    (push_word),
    .crc_out (crc_next)
  );

  logic [WORD_W:0] fifo_tdata;

  buf_out_fifo #(.WIDTH(WORD_W + 1), .DEPTH(4), .LATENCY(2)) u_out (
    .clk           (clk),
    .rst           (rst),
    .can_issue     (can_issue),
    .issue         (issue),
    .in_data       ({p2_last_q, p2_crc_q ? WORD_W'(crc_sent) : push_word}),
    .m_axis_tdata  (fifo_tdata),
    .m_axis_tvalid (m_axis_tvalid),
    .m_axis_tready (m_axis_tready)
  );
  assign m_axis_tdata = fifo_tdata[WORD_W-1:0];
  assign m_axis_tlast = fifo_tdata[WORD_W];

  // Descriptor of the packet that closes with this input word. It is written only on a beat
  // that stores (a packet that stores a word also stores its closing word: only this side
  // sets its bank full, at the close, so space does not go away while a packet is open;
  // formal: wr_cnt_q != 0 -> space, and a write has beat && store), so its fields take
  // beat = store = space = 1: none reads the input handshake (timing: the TREADY decision,
  // behind the packet-count check, stays out of the descriptor's data)
  desc_t new_desc;
  always_comb begin
    new_desc          = '0;
    new_desc.len      = wr_cnt_q + 1'b1;  // cnt_next with store
    new_desc.last_idx = wr_cnt_q;         // len - 1
    new_desc.drops    = wr_drop_q;        // drop_next without a drop
    new_desc.seq      = seq_q;
    new_desc.npkt     = dv_np_q;
    new_desc.frame    = frame_q;
    new_desc.last     = frame_end;
    new_desc.ovf      = ovf_q;
    new_desc.framing  = framing_q || tlast_bad;
    new_desc.damaged  = wr_dmg_q || s_axis_tuser[0];
  end

  // ---------------------------------------------------------------------------------------
  // s_axis_tready as a register (the decision: the input side's comment)
  function automatic logic ready_of(input logic sp, input logic fz, input logic busy,
                                    input logic hit, input logic fe);
    ready_of = sp && (!busy || !pkt_end_of(fz, hit, fe));
  endfunction
  // A packet that closes with a word stored or stored before fills its bank (desc_we); a
  // bank the input side sets is not the one the output side clears (the set first).
  assign full_d      = (full_q | (desc_we ? NUM_BANKS'(1) << wr_bank_q : '0))
                       & ~((issue_data && rd_last) ? NUM_BANKS'(1) << rd_bank_q : '0);
  assign wr_bank_d   = wr_bank_q + BANK_W'(desc_we);
  assign fw_zero_d   = beat ? frame_end : fw_zero_q;
  assign frame_end_d = beat ? (frame_end ? (FRAME_WORDS == 1)
                                         : (fw_q == FWC_W'(FRAME_WORDS - 2)))
                            : frame_end_q;
  assign pos_hit_d   = beat ? pos_hit_next : pos_hit_q;
  always_ff @(posedge clk) begin
    if (rst) tready_q <= 1'b1;  // (the reset state: banks free, divider idle)
    else     tready_q <= ready_of(!full_d[wr_bank_d], fw_zero_d, dv_busy_d, pos_hit_d,
                                  frame_end_d);
  end
  if (!INPUT_BACKPRESSURE) begin : g_tready_one
    assign s_axis_tready = 1'b1;
  end else if (FRAME_WORDS == 1) begin : g_tready_comb
    assign s_axis_tready = space && npkt_ok;
  end else begin : g_tready_reg
    assign s_axis_tready = tready_q;
  end

  // ---------------------------------------------------------------------------------------
  // Registers
  always_ff @(posedge clk) begin
    p_hdr_q      <= issue_hdr;
    p_data_q     <= issue_data;
    p_crc_q      <= issue_crc;
    p_last_q     <= HEADER ? issue_crc : (issue_data && rd_last);
    p_hdr_word_q <= hdr_word;
    p2_hdr_q      <= p_hdr_q;
    p2_data_q     <= p_data_q;
    p2_crc_q      <= p_crc_q;
    p2_last_q     <= p_last_q;
    p2_hdr_word_q <= p_hdr_word_q;
    if (p2_hdr_q || p2_data_q) crc_q <= crc_next;
    if (desc_we) desc_q[wr_bank_q] <= new_desc;
  end

  always_ff @(posedge clk) begin
    if (rst) begin
      full_q        <= '0;
      wr_bank_q     <= '0;
      pos_q         <= '0;
      wr_cnt_q      <= '0;
      wr_drop_q     <= '0;
      wr_dmg_q      <= 1'b0;
      seq_q         <= '0;
      fw_q          <= '0;
      fw_zero_q     <= 1'b1;
      frame_end_q   <= (FRAME_WORDS == 1);
      pos_hit_q     <= 1'b0;  // (pw_q = PACKET_WORDS >= 2)
      pw_q          <= LEN_W'(PACKET_WORDS);
      frame_q       <= '0;
      tl_pos_q      <= '0;
      ovf_q         <= 1'b0;
      framing_q     <= 1'b0;
      drop_cnt_q    <= '0;
      framing_cnt_q <= '0;
      frame_cnt_q   <= '0;
      packet_cnt_q  <= '0;
      rd_bank_q     <= '0;
      rd_idx_q      <= '0;
      hdr_sent_q    <= 1'b0;
      crc_due_q     <= 1'b0;
    end else begin
      // the bank ring and the look-ahead flags (their next state above, for tready_q)
      full_q      <= full_d;
      wr_bank_q   <= wr_bank_d;
      fw_zero_q   <= fw_zero_d;
      frame_end_q <= frame_end_d;
      pos_hit_q   <= pos_hit_d;
      // input side
      if (beat) begin
        tl_pos_q <= (tl_pos_q == TLP_W'(TLP - 1) || frame_end) ? '0 : tl_pos_q + 1'b1;
        fw_q     <= frame_end ? '0 : fw_q + 1'b1;
        if (fw_zero_q) pw_q <= pw;
        if (!space) begin
          ovf_q <= 1'b1;
          if (drop_cnt_q != '1) drop_cnt_q <= drop_cnt_q + 1'b1;
        end
        if (tlast_err) begin
          framing_q <= 1'b1;
          if (framing_cnt_q != '1) framing_cnt_q <= framing_cnt_q + 1'b1;
        end
        if (pkt_end) begin
          pos_q     <= '0;
          wr_cnt_q  <= '0;
          wr_drop_q <= '0;
          wr_dmg_q  <= 1'b0;
          seq_q     <= frame_end ? '0 : seq_q + 1'b1;
          if (frame_end) begin
            frame_q     <= frame_q + 1'b1;
            frame_cnt_q <= frame_cnt_q + 1'b1;
          end
        end else begin
          pos_q     <= pos_q + 1'b1;
          wr_cnt_q  <= cnt_next;
          wr_drop_q <= drop_next;
          wr_dmg_q  <= wr_dmg_q || s_axis_tuser[0];
        end
      end
      // output side (never clears the bank the input side sets: that one is not full)
      if (issue_hdr) hdr_sent_q <= 1'b1;
      if (issue_crc) crc_due_q <= 1'b0;
      if (issue_data) begin
        if (rd_last) begin
          rd_idx_q          <= '0;
          hdr_sent_q        <= 1'b0;
          crc_due_q         <= HEADER;
          rd_bank_q         <= rd_bank_q + 1'b1;
          packet_cnt_q      <= packet_cnt_q + 1'b1;
        end else begin
          rd_idx_q <= rd_idx_q + 1'b1;
        end
      end
    end
  end

`ifndef SYNTHESIS
`ifndef FORMAL  // (formal/axis_packetizer.sby fixes the length instead)
  // the run-time length is legal where it is taken (a frame's first word)
  always_ff @(posedge clk) begin
    if (!rst && beat && fw_q == '0)
      assert (32'(cfg_packet_words) >= 32'(PW_MIN) && 32'(cfg_packet_words) <= PACKET_WORDS
              && (INPUT_BACKPRESSURE || 32'(cfg_packet_words) == PACKET_WORDS))
        else $error("%m: cfg_packet_words=%0d not in %0d..%0d", cfg_packet_words, PW_MIN,
                    PACKET_WORDS);
    // npkt_ok's premise: the divider's operand is the frame's length past its first word
    if (!rst && !fw_zero_q)
      assert (dv_op_q == pw_q)
        else $error("%m: divider operand %0d, frame length %0d", dv_op_q, pw_q);
    // tready_q is the decision on the registers (with the run-time length changing)
    if (!rst && INPUT_BACKPRESSURE && FRAME_WORDS > 1)
      assert (s_axis_tready == (space && (npkt_ok || !pkt_end)))
        else $error("%m: registered TREADY %0b differs from its decision", s_axis_tready);
  end
`endif
`endif

  assign status_overflow      = ovf_q;
  assign status_framing_error = framing_q;
  assign drop_count           = drop_cnt_q;
  assign framing_error_count  = framing_cnt_q;
  assign frame_count          = frame_cnt_q;
  assign packet_count         = packet_cnt_q;

`ifdef FORMAL
  // Formal properties (formal/axis_packetizer.sby). Sequence numbers and packet lengths:
  // the open packet's position and sequence number stay inside the frame's packet plan;
  // the full banks form a contiguous ring from rd_bank_q; every stored descriptor holds a
  // sequence number < NPKT, LAST exactly on the frame's last packet, and (no drops) the
  // planned length; consecutive full banks hold consecutive sequence numbers; a bank under
  // input is never read; sticky flags. bmc adds the output framing: each packet is
  // HEADER + its planned length + HEADER (the CRC word) words closed by TLAST, its header
  // carries MAGIC and the expected sequence number.
  logic                  f_past = 1'b0;
  logic [SEQ_W-1:0]      f_out_seq = '0;
  logic [LEN_W:0]        f_out_pos = '0;
  logic [BANK_W:0]       f_nfull;
  logic [BANK_W-1:0]     f_b, f_nb;
  desc_t                 f_d, f_dn;
  initial assume (rst);
  always_ff @(posedge clk) begin
    f_past <= 1'b1;
    if (rst) begin
      f_out_seq <= '0;
      f_out_pos <= '0;
    end else if (m_axis_tvalid && m_axis_tready) begin
      f_out_pos <= m_axis_tlast ? '0 : f_out_pos + 1'b1;
      if (m_axis_tlast) f_out_seq <= (f_out_seq == SEQ_W'(NPKT - 1)) ? '0 : f_out_seq + 1'b1;
    end
  end
  always_comb begin
    f_nfull = '0;
    for (int i = 0; i < NUM_BANKS; i++) f_nfull = f_nfull + (BANK_W+1)'(full_q[i]);
  end
  always_comb begin
    f_b  = '0;
    f_nb = '0;
    f_d  = '0;
    f_dn = '0;
    if (f_past && !rst) begin
      assume (frame_q != '1);
      // the packet plan below is the one of PACKET_WORDS (the run-time length fixed there)
      assume (cfg_packet_words == 16'(PACKET_WORDS));
      assert (pw_q == LEN_W'(PACKET_WORDS) && dv_op_q == LEN_W'(PACKET_WORDS));
      // the registered TREADY is the decision on the current registers
      if (INPUT_BACKPRESSURE)
        assert (s_axis_tready == (space && (npkt_ok || !pkt_end)));
      assert (!dv_busy_q && dv_np_q == NP_W'(NPKT));
      assert (32'(fw_q) == 32'(seq_q) * PACKET_WORDS + 32'(pos_q));
      assert (fw_zero_q == (fw_q == '0) && frame_end_q == (fw_q == FWC_W'(FRAME_WORDS - 1)));
      if (fw_zero_q) assert (pos_q == '0);
      else assert (pos_hit_q == (LEN_W'(pos_q) == pw_q - 1'b1));
      assert (32'(wr_cnt_q) <= 32'(pos_q));
      if (wr_cnt_q != '0) assert (space);  // (new_desc.last_idx)
      // a descriptor is written only with a word stored (new_desc's fields take beat = 1)
      if (desc_we) assert (store);
      assert (seq_q <= SEQ_W'(NPKT - 1));
      assert ({1'b0, pos_q} <= (POS_W+1)'(PACKET_WORDS - 1));
      if (seq_q == SEQ_W'(NPKT - 1)) assert ({1'b0, pos_q} <= (POS_W+1)'(LAST_LEN - 1));
      if (INPUT_BACKPRESSURE) assert (LEN_W'(pos_q) == wr_cnt_q && wr_drop_q == '0 && !ovf_q);
      // ring of full banks from the read bank to the write bank
      assert ((BANK_W+1)'(BANK_W'(wr_bank_q - rd_bank_q)) == f_nfull ||
              (wr_bank_q == rd_bank_q && f_nfull == (BANK_W+1)'(NUM_BANKS)));
      if (!full_q[rd_bank_q]) assert (rd_idx_q == '0 && !hdr_sent_q);
      if (crc_due_q) assert (HEADER && rd_idx_q == '0 && !hdr_sent_q);
      for (int i = 0; i < NUM_BANKS; i++) begin
        f_b  = rd_bank_q + BANK_W'(i);
        f_nb = f_b + 1'b1;
        f_d  = desc_q[f_b];
        f_dn = desc_q[f_nb];
        if (full_q[f_b]) begin
          assert (f_d.seq <= SEQ_W'(NPKT - 1));
          assert (f_d.last == (f_d.seq == SEQ_W'(NPKT - 1)));
          assert (f_d.len != '0 && f_d.len <= LEN_W'(PACKET_WORDS));
          assert (f_d.last_idx == f_d.len - 1'b1);
          if (INPUT_BACKPRESSURE) begin
            assert (f_d.drops == '0);
            assert (f_d.len == (f_d.last ? LEN_W'(LAST_LEN) : LEN_W'(PACKET_WORDS)));
            // the next packet (stored or open) carries the next sequence number
            if (full_q[f_nb] && f_nb != rd_bank_q)
              assert (f_dn.seq == (f_d.last ? '0 : f_d.seq + 1'b1));
            if (f_nb == wr_bank_q)
              assert (seq_q == (f_d.last ? '0 : f_d.seq + 1'b1));
          end
        end
      end
      if (full_q[rd_bank_q]) assert (LEN_W'(rd_idx_q) < rd_desc.len);
      if (store) assert (!full_q[wr_bank_q]);
`ifdef F_OUTPUT_FRAMING
      if (m_axis_tvalid) begin
        if (f_out_pos == '0 && HEADER) begin
          assert (m_axis_tdata[31:24] == MAGIC && m_axis_tdata[15:4] == f_out_seq);
          assert (!m_axis_tlast);
        end
        if (INPUT_BACKPRESSURE)
          assert (m_axis_tlast == (f_out_pos == (LEN_W+1)'(2 * HEADER) - 1'b1 +
                   ((f_out_seq == SEQ_W'(NPKT - 1)) ? (LEN_W+1)'(LAST_LEN) :
                                                       (LEN_W+1)'(PACKET_WORDS))));
      end
`endif
    end
  end
  always_ff @(posedge clk) if (f_past && !$past(rst) && !rst) begin
    if ($past(ovf_q)) assert (ovf_q);
    if ($past(framing_q)) assert (framing_q);
  end
  always_comb if (f_past && !rst) begin
    cover (f_nfull == (BANK_W+1)'(NUM_BANKS));
    cover (m_axis_tvalid && m_axis_tlast && !m_axis_tready && f_out_seq == SEQ_W'(NPKT - 1));
    cover (frame_cnt_q == 32'd2);
    cover (framing_q || ovf_q);
  end
`endif

  // AXI4-Stream protocol on every port (rtl/common/axis_checker.sv)
  axis_checker #(.PAYLOAD_W(NUM_RX*32 + 2), .ASSUME(1'b1)) u_chk_s_axis (
    .clk, .rst, .tvalid(s_axis_tvalid), .tready(s_axis_tready),
    .payload({s_axis_tuser, s_axis_tlast, s_axis_tdata}));
  axis_checker #(.PAYLOAD_W(NUM_RX*32 + 1)) u_chk_m_axis (
    .clk, .rst, .tvalid(m_axis_tvalid), .tready(m_axis_tready),
    .payload({m_axis_tlast, m_axis_tdata}));

endmodule

`default_nettype wire
