// SPDX-License-Identifier: Apache-2.0
// In-place corner turn (frame transpose) between the range FFT and the Doppler FFT: one frame
// of memory, written chirp by chirp, read as per-TX Doppler vectors while the next frame is
// written into the slots just read.
//
// Input word i of a frame (i = (d*NUM_TX + t)*N_RANGE + r, chirp c = d*NUM_TX + t sent by
// TX t, range bin r) and output word j (j = (t*N_RANGE + r)*N_DOPPLER + d), N words a frame:
// the reorder maps output j to input p(j) = j*M mod (N-1), M = NUM_TX*N_RANGE (p(N-1) = N-1).
// In-place scheme: frame k is written at addresses W_k(i) = p^k(i) = i*M^k mod (N-1) and read
// at R_k(j) = W_k(p(j)) = W_{k+1}(j), so frame k+1's word i goes to the slot that frame k's
// read number i has just freed. For a power-of-two NUM_TX (N = 2^B) this is the bit rotation
// rotl(i, k*ROT mod B), ROT = log2(M); any other NUM_TX steps the address by the stride M^k
// mod (N-1). The writer only ever trails the reader (write count < read count), which is when
// s_axis_tready is low. READ_ORDER 1: below. Details and memory figures: docs/buffers.md.
//
// N_LOOPS < N_DOPPLER (fewer loops than the Doppler FFT length, which zero-fills): a frame
// is the first N_LOOPS chirps per TX (input words i < NUM_TX*N_RANGE*N_LOOPS, the top index
// field is d) and a Doppler vector its first N_LOOPS words (d < N_LOOPS): both counters skip
// the indices of the missing loops, so the scheme above holds unchanged on the words that
// exist (a slot a frame's read skips held no word of that frame). Address stepping jumps
// over the skipped words at each vector end (stride (N_DOPPLER-N_LOOPS+1)*M^(k+1) mod (N-1)).
`default_nettype none

module corner_turn #(
  // TX slots (TDM chirps interleaved), 1..16 (READ_ORDER 1 with a count that is not a
  // power of two: TX banks, docs/buffers.md).
  parameter int NUM_TX = 1,
  // Receive lanes per word, 1..64.
  parameter int NUM_RX = 4,
  // Range bins per chirp (words per input chirp), power of two, 2..4096.
  parameter int N_RANGE = 64,
  // Chirps per TX per frame the memory holds (the Doppler FFT length), power of two, 2..4096.
  parameter int N_DOPPLER = 256,
  // Chirps per TX per frame (loops; output Doppler vector length), 1..N_DOPPLER.
  parameter int N_LOOPS = N_DOPPLER,
  // Bits of I and of Q per lane, 8..32.
  parameter int DATA_W = 16,
  // Output order. 0: for TX t, for range bin r (the radar cube, docs/design.md 3.2);
  // 1: for range bin r, for TX t (on-chip detection, docs/detect.md: all TX of a range bin
  // together). The Doppler vector is the same; with NUM_TX = 1 both orders are equal.
  parameter int READ_ORDER = 0,
  // Frame-memory banks (buf_sdp_ram BANKS): 1, or with a power-of-two NUM_TX a power of two
  // 2..NUM_TX*N_RANGE*N_DOPPLER/2: the memory split by its top address bits, the bank chosen
  // after the per-bank output registers (for synthesis that does not use the block RAM's own
  // output register: the ECP5 timing flow sets 8). Same data and timing at the ports.
  parameter int RAM_BANKS = 1
) (
  input  wire logic                          clk,
  input  wire logic                          rst,
  // Range FFT output: chirp by chirp, TLAST on range bin N_RANGE-1 of every chirp
  input  wire logic [NUM_RX*2*DATA_W-1:0]    s_axis_tdata,
  input  wire logic                          s_axis_tvalid,
  output logic                               s_axis_tready,
  input  wire logic                          s_axis_tlast,
  // Doppler vectors: for TX t, for range bin r, N_LOOPS words (chirps of TX t in order),
  // TLAST on the last word of every vector, TUSER[0] on the first word of every frame
  output logic      [NUM_RX*2*DATA_W-1:0]    m_axis_tdata,
  output logic                               m_axis_tvalid,
  input  wire logic                          m_axis_tready,
  output logic                               m_axis_tlast,
  output logic      [0:0]                    m_axis_tuser,
  // Status (cleared only by rst)
  output logic                               status_framing_error, // sticky: misplaced TLAST
  output logic      [31:0]                   framing_error_count,  // misplaced/missing TLASTs
  output logic      [31:0]                   frames_in,            // frames completely written
  output logic      [31:0]                   frames_out            // frames completely read
);

  localparam int WORD_W = NUM_RX * 2 * DATA_W;
  localparam int BT     = $clog2(NUM_TX);
  localparam int BR     = $clog2(N_RANGE);
  localparam int BD     = $clog2(N_DOPPLER);
  localparam bit POW2   = (1 << BT) == NUM_TX;     // frame of 2^B words
  localparam int N      = NUM_TX * N_RANGE * N_DOPPLER;   // words per frame
  localparam int B      = BT + BR + BD;           // address bits (N <= 2^B)
  // rotated index: the whole frame (power-of-two NUM_TX) or one TX bank (READ_ORDER 1)
  localparam int RB     = POW2 ? B : BR + BD;
  localparam int ROT    = POW2 ? BT + BR : BR;    // rotation per frame
  localparam int SH_W   = $clog2(RB);

  // Parameter checks: stop elaboration on illegal values.
  if (NUM_TX < 1 || NUM_TX > 16) begin : g_bad_num_tx
    $fatal(1, "%m: NUM_TX=%0d not in 1..16", NUM_TX);
  end
  if (NUM_RX < 1 || NUM_RX > 64) begin : g_bad_num_rx
    $fatal(1, "%m: NUM_RX=%0d not in 1..64", NUM_RX);
  end
  if (N_RANGE < 2 || N_RANGE > 4096 || (1 << BR) != N_RANGE) begin : g_bad_n_range
    $fatal(1, "%m: N_RANGE=%0d must be a power of two in 2..4096", N_RANGE);
  end
  if (N_DOPPLER < 2 || N_DOPPLER > 4096 || (1 << BD) != N_DOPPLER) begin : g_bad_n_doppler
    $fatal(1, "%m: N_DOPPLER=%0d must be a power of two in 2..4096", N_DOPPLER);
  end
  if (N_LOOPS < 1 || N_LOOPS > N_DOPPLER) begin : g_bad_n_loops
    $fatal(1, "%m: N_LOOPS=%0d not in 1..N_DOPPLER (%0d)", N_LOOPS, N_DOPPLER);
  end
  if (DATA_W < 8 || DATA_W > 32) begin : g_bad_data_w
    $fatal(1, "%m: DATA_W=%0d not in 8..32", DATA_W);
  end
  if (B > 24) begin : g_bad_frame_words
    $fatal(1, "%m: NUM_TX*N_RANGE*N_DOPPLER above 2^24 words");
  end
  if (READ_ORDER < 0 || READ_ORDER > 1) begin : g_bad_read_order
    $fatal(1, "%m: READ_ORDER=%0d not 0 or 1", READ_ORDER);
  end

  // rotl(x, s) on RB bits, 0 <= s < RB
  // (function results assigned to the function name: Yosys does not parse `return`)
  function automatic logic [RB-1:0] rotl(input logic [RB-1:0] x, input logic [SH_W-1:0] s);
    rotl = RB'({x, x} >> (RB - 32'(s)));
  endfunction

  // (a + ROT) mod RB for a shift amount a < RB
  function automatic logic [SH_W-1:0] next_shift(input logic [SH_W-1:0] a);
    logic [SH_W:0] t;
    t = {1'b0, a} + (SH_W+1)'(ROT);
    if (t >= (SH_W+1)'(RB)) t = t - (SH_W+1)'(RB);
    next_shift = t[SH_W-1:0];
  endfunction

  // ---------------------------------------------------------------------------------------
  // Frame memory (one frame, simple dual port, registered read and output register: a read
  // issued at clock t enters the output FIFO at t+2)
  logic              ram_wr_en, ram_rd_en;
  logic [B-1:0]      ram_wr_addr, ram_rd_addr;
  logic [WORD_W-1:0] ram_rd_data;

  buf_sdp_ram #(.WIDTH(WORD_W), .DEPTH(N), .OUT_REG(1'b1), .BANKS(RAM_BANKS)) u_ram (
    .clk     (clk),
    .wr_en   (ram_wr_en),
    .wr_addr (ram_wr_addr),
    .wr_data (s_axis_tdata),
    .rd_en   (ram_rd_en),
    .rd_addr (ram_rd_addr),
    .rd_data (ram_rd_data)
  );

  // ---------------------------------------------------------------------------------------
  // Write side
  logic [B-1:0]    wr_cnt_q;     // input word index within the frame
  logic [SH_W-1:0] wr_shift_q;   // k*ROT mod B for the frame being written
  logic            pending_q;    // a completely written frame waits for the reader
  logic            framing_q;
  logic            framing_ev_q; // a misplaced/missing TLAST was taken last clock
  logic [31:0]     framing_cnt_q, frames_in_q, frames_out_q;
  logic            wr_beat, wr_frame_end, chirp_end, wr_free;

  // Read side
  logic [B-1:0]    rd_cnt_q;     // output word index (reads issued) within the frame
  logic [SH_W-1:0] rd_shift_q;   // (k+1)*ROT mod B for the frame being read
  logic            rd_active_q;
  logic            can_issue, rd_issue, rd_start, rd_frame_end;
  logic            p_last_q, p_sof_q, p2_last_q, p2_sof_q;

  // Last input word of a frame and last read of a frame; the read skips d >= N_LOOPS.
  localparam logic [B-1:0] WR_LAST = B'(NUM_TX * N_RANGE * N_LOOPS - 1);
  localparam logic [B-1:0] RD_LAST = B'(N - N_DOPPLER + N_LOOPS - 1);
  logic         rd_vec_end;
  logic [B-1:0] rd_next;
  assign rd_vec_end = (rd_cnt_q[BD-1:0] == BD'(N_LOOPS - 1));
  assign rd_next    = rd_vec_end ? {rd_cnt_q[B-1:BD] + 1'b1, BD'(0)} : rd_cnt_q + 1'b1;

  // The writer may use slot W_{k+1}(i) = R_k(i) only once read i was issued (earlier clock):
  // wr_free (TX banks: once its bank's read of the same bank word was issued).
  assign s_axis_tready = !rst && !pending_q && (!rd_active_q || wr_free);
  assign wr_beat       = s_axis_tvalid && s_axis_tready;
  assign wr_frame_end  = (wr_cnt_q == WR_LAST);
  assign chirp_end     = (wr_cnt_q[BR-1:0] == '1);
  assign ram_wr_en     = wr_beat;

  assign rd_start    = pending_q && !rd_active_q;
  assign rd_issue    = rd_active_q && can_issue;
  assign ram_rd_en   = rd_issue;

  // Addresses. READ_ORDER 0: W_k(i) = rotl(i, k*ROT mod B) (header comment).
  // READ_ORDER 1: output j = (r*NUM_TX + t)*N_DOPPLER + d maps to input p(j), a bit
  // permutation (not a rotation): bit a of p(j) is bit SIGMA[a] of j. The in-place scheme
  // holds for any bit permutation: W_k = p^k, whose bit a is bit sigma_k[a] of the index,
  // sigma_0 = identity, sigma_{k+1}[a] = SIGMA[sigma_k[a]]; the read of frame k uses
  // sigma_{k+1} (= W_{k+1}, as for the rotation).
  if (POW2 && READ_ORDER == 0) begin : g_rot
    assign ram_wr_addr = rotl(wr_cnt_q, wr_shift_q);
    assign ram_rd_addr = rotl(rd_cnt_q, rd_shift_q);
    assign wr_free     = (wr_cnt_q < rd_cnt_q);
  end else if (POW2) begin : g_perm
    // SIGMA[a]: input-index bits are {d, t, r} (r lowest), output-index bits {r, t, d}
    function automatic logic [SH_W-1:0] sigma(input int a);
      if (a < BR)           sigma = SH_W'(BT + BD + a);        // r
      else if (a < BR + BT) sigma = SH_W'(BD + (a - BR));       // t
      else                  sigma = SH_W'(a - BR - BT);         // d
    endfunction
    logic [SH_W-1:0] wr_perm_q [B];
    logic [SH_W-1:0] rd_perm_q [B];
    always_ff @(posedge clk) begin
      if (rst) begin
        for (int a = 0; a < B; a++) wr_perm_q[a] <= SH_W'(a);
      end else if (wr_beat && wr_frame_end) begin
        for (int a = 0; a < B; a++) begin
          for (int c = 0; c < B; c++) if (wr_perm_q[a] == SH_W'(c)) wr_perm_q[a] <= sigma(c);
        end
      end
      if (rd_start) rd_perm_q <= wr_perm_q;   // already advanced to sigma_{k+1}
    end
    always_comb begin
      for (int a = 0; a < B; a++) begin
        ram_wr_addr[a] = wr_cnt_q[wr_perm_q[a]];
        ram_rd_addr[a] = rd_cnt_q[rd_perm_q[a]];
      end
    end
    assign wr_free = (wr_cnt_q < rd_cnt_q);
    logic unused_rot;
    assign unused_rot = ^{rd_shift_q};
  end else if (READ_ORDER == 0) begin : g_mod
    // Any NUM_TX: address += stride mod (N-1), word N-1 at slot N-1. Strides M^k mod (N-1)
    // of the frame written (ws_q) and read (rs_q, = the writer's next); the next stride
    // is computed while a frame is written, NUM_TX-1 modular additions (x NUM_TX) then BR
    // doublings (x N_RANGE), fewer clocks than the frame's words. N_LOOPS < N_DOPPLER: the
    // read jumps over the N_DOPPLER-N_LOOPS skipped words at each vector end, address +=
    // J = (N_DOPPLER-N_LOOPS+1)*M^(k+1) mod (N-1), kept as (N_DOPPLER-N_LOOPS+1)*M^k
    // beside the stride (wj_q) and multiplied by M in the same engine steps.
    localparam logic [B-1:0] NM1 = B'(N - 1);
    localparam bit SKIP = N_LOOPS < N_DOPPLER;
    localparam logic [B-1:0] JUMP0 = B'(N_DOPPLER - N_LOOPS + 1);   // < N-1
    localparam int ES = NUM_TX - 1 + BR;            // stride engine steps
    localparam int EW = $clog2(ES + 1);
    function automatic logic [B-1:0] modadd(input logic [B-1:0] a, input logic [B-1:0] b);
      logic [B:0] t;
      t = {1'b0, a} + {1'b0, b};
      if (t >= {1'b0, NM1}) t = t - {1'b0, NM1};
      modadd = t[B-1:0];
    endfunction
    logic [B-1:0]  ws_q, rs_q, wa_q, ra_q, acc_q, wj_q, rj_q, jacc_q;
    logic [EW-1:0] e_q;
    always_ff @(posedge clk) begin
      if (rst) begin
        ws_q  <= B'(1);
        acc_q <= B'(1);
        e_q   <= '0;
        wa_q  <= '0;
        rs_q  <= B'(1);
        ra_q  <= '0;
        wj_q   <= JUMP0;
        jacc_q <= JUMP0;
        rj_q   <= JUMP0;
      end else begin
        if (e_q != EW'(ES)) begin
          acc_q  <= modadd(acc_q, (e_q < EW'(NUM_TX - 1)) ? ws_q : acc_q);
          jacc_q <= modadd(jacc_q, (e_q < EW'(NUM_TX - 1)) ? wj_q : jacc_q);
          e_q    <= e_q + 1'b1;
        end
        if (wr_beat) begin
          wa_q <= (wr_cnt_q == B'(N - 2)) ? NM1 : modadd(wa_q, ws_q);
          if (wr_frame_end) begin
            wa_q <= '0;
            ws_q <= acc_q;          // M^(k+1): the engine finished within the frame
            wj_q <= jacc_q;
            e_q  <= '0;
          end
        end
        if (rd_start) begin
          rs_q <= ws_q;             // already advanced to M^(k+1)
          rj_q <= wj_q;
          ra_q <= '0;
        end else if (rd_issue) begin
          ra_q <= (rd_cnt_q == B'(N - 2)) ? NM1 :
                  modadd(ra_q, (SKIP && rd_vec_end) ? rj_q : rs_q);
        end
      end
    end
    assign ram_wr_addr = wa_q;
    assign ram_rd_addr = ra_q;
    assign wr_free     = (wr_cnt_q < rd_cnt_q);
    logic unused_shift;
    assign unused_shift = ^{wr_shift_q, rd_shift_q};
  end else begin : g_bank
    // READ_ORDER 1, NUM_TX not a power of two: NUM_TX banks of N_RANGE*N_DOPPLER words,
    // bank t an in-place N_DOPPLER x N_RANGE transpose of TX t's chirps (bank word {d, r}
    // written at rotl({d, r}, k*BR mod RB), bank word {r, d} read at rotl({r, d},
    // (k+1)*BR mod RB)). A write waits for its bank's read of the same bank word; with
    // N_LOOPS < N_DOPPLER each bank skips as the power-of-two scheme does (rd_done counts a
    // bank row's skipped reads d >= N_LOOPS as done once the reader has passed the row).
    logic [BD-1:0] wd_q;            // writer chirp index d (r = wr_cnt_q[BR-1:0])
    logic [BT-1:0] wt_q, rt_q;      // writer / reader TX
    logic [BR-1:0] rr_q;            // reader range bin (d = rd_cnt_q[BD-1:0])
    logic [RB:0]   rd_done;         // reads issued in the writer's bank
    always_ff @(posedge clk) begin
      if (rst) begin
        wd_q <= '0;
        wt_q <= '0;
        rt_q <= '0;
        rr_q <= '0;
      end else begin
        if (wr_beat && chirp_end) begin
          wt_q <= (wt_q == BT'(NUM_TX - 1)) ? '0 : wt_q + 1'b1;
          if (wt_q == BT'(NUM_TX - 1)) wd_q <= wr_frame_end ? '0 : wd_q + 1'b1;
        end
        if (rd_issue && rd_vec_end) begin
          rt_q <= (rt_q == BT'(NUM_TX - 1)) ? '0 : rt_q + 1'b1;
          if (rt_q == BT'(NUM_TX - 1)) rr_q <= rr_q + 1'b1;
        end
      end
    end
    always_comb begin
      rd_done = {1'b0, rr_q, BD'(0)};
      if (wt_q < rt_q) rd_done = rd_done + (RB+1)'(N_DOPPLER);
      else if (wt_q == rt_q) rd_done = rd_done + (RB+1)'(rd_cnt_q[BD-1:0]);
    end
    assign wr_free     = ({1'b0, wd_q, wr_cnt_q[BR-1:0]} < rd_done);
    assign ram_wr_addr = {wt_q, rotl({wd_q, wr_cnt_q[BR-1:0]}, wr_shift_q)};
    assign ram_rd_addr = {rt_q, rotl({rr_q, rd_cnt_q[BD-1:0]}, rd_shift_q)};
  end

  assign rd_frame_end = (rd_cnt_q == RD_LAST);

  always_ff @(posedge clk) begin
    p_last_q  <= rd_vec_end;
    p_sof_q   <= (rd_cnt_q == '0);
    p2_last_q <= p_last_q;
    p2_sof_q  <= p_sof_q;
  end

  always_ff @(posedge clk) begin
    if (rst) begin
      wr_cnt_q      <= '0;
      wr_shift_q    <= '0;
      pending_q     <= 1'b0;
      framing_q     <= 1'b0;
      framing_ev_q  <= 1'b0;
      framing_cnt_q <= '0;
      frames_in_q   <= '0;
      frames_out_q  <= '0;
      rd_cnt_q      <= '0;
      rd_shift_q    <= '0;
      rd_active_q   <= 1'b0;
    end else begin
      // The framing flag and counter follow the beat by one clock (docs/synth.md note 26:
      // the counter sits by the status logic, far from the input handshake).
      framing_ev_q <= wr_beat && (s_axis_tlast != chirp_end);
      if (framing_ev_q) begin
        framing_q <= 1'b1;
        if (framing_cnt_q != '1) framing_cnt_q <= framing_cnt_q + 1'b1;
      end
      if (wr_beat) begin
        wr_cnt_q <= wr_frame_end ? '0 : wr_cnt_q + 1'b1;
        if (wr_frame_end) begin
          pending_q   <= 1'b1;
          wr_shift_q  <= next_shift(wr_shift_q);
          frames_in_q <= frames_in_q + 1'b1;
        end
      end
      if (rd_start) begin
        // the writer already advanced wr_shift_q to (k+1)*ROT: exactly the read shift
        rd_active_q <= 1'b1;
        pending_q   <= 1'b0;
        rd_shift_q  <= wr_shift_q;
      end
      if (rd_issue) begin
        rd_cnt_q <= rd_frame_end ? '0 : rd_next;
        if (rd_frame_end) begin
          rd_active_q  <= 1'b0;
          frames_out_q <= frames_out_q + 1'b1;
        end
      end
    end
  end

  // ---------------------------------------------------------------------------------------
  // Output
  logic [WORD_W+1:0] fifo_tdata;

  buf_out_fifo #(.WIDTH(WORD_W + 2), .DEPTH(4), .LATENCY(2)) u_out (
    .clk           (clk),
    .rst           (rst),
    .can_issue     (can_issue),
    .issue         (rd_issue),
    .in_data       ({p2_sof_q, p2_last_q, ram_rd_data}),
    .m_axis_tdata  (fifo_tdata),
    .m_axis_tvalid (m_axis_tvalid),
    .m_axis_tready (m_axis_tready)
  );
  assign m_axis_tdata    = fifo_tdata[WORD_W-1:0];
  assign m_axis_tlast    = fifo_tdata[WORD_W];
  assign m_axis_tuser[0] = fifo_tdata[WORD_W+1];

  assign status_framing_error = framing_q;
  assign framing_error_count  = framing_cnt_q;
  assign frames_in            = frames_in_q;
  assign frames_out           = frames_out_q;

  // AXI4-Stream protocol on every port (rtl/common/axis_checker.sv)
  axis_checker #(.PAYLOAD_W(NUM_RX*2*DATA_W + 1), .ASSUME(1'b1)) u_chk_s_axis (
    .clk, .rst, .tvalid(s_axis_tvalid), .tready(s_axis_tready),
    .payload({s_axis_tlast, s_axis_tdata}));
  axis_checker #(.PAYLOAD_W(NUM_RX*2*DATA_W + 2)) u_chk_m_axis (
    .clk, .rst, .tvalid(m_axis_tvalid), .tready(m_axis_tready),
    .payload({m_axis_tuser, m_axis_tlast, m_axis_tdata}));

`ifdef FORMAL
  // Formal properties (formal/corner_turn.sby). In place: a slot is written only after the
  // previous frame's word in it was read (f_pend: written, not yet read; write never hits an
  // unread slot, read never hits an unwritten one), the writer never overtakes the reader,
  // reader and writer agree on the frame's rotation; no beat created or lost (words read ==
  // words written, frame by frame); output TLAST every N_DOPPLER words, TUSER on word 0
  // (bounded: those sit in the output FIFO).
  logic             f_past = 1'b0;
  logic [(1<<B)-1:0] f_pend = '0;
  logic [B-1:0]     f_out_pos = '0;
  logic [7:0]       f_words_in = '0, f_words_out = '0;
  initial assume (rst);
  always_ff @(posedge clk) begin
    f_past <= 1'b1;
    if (rst) begin
      f_pend      <= '0;
      f_out_pos   <= '0;
      f_words_in  <= '0;
      f_words_out <= '0;
    end else begin
      if (rd_issue) f_pend[ram_rd_addr] <= 1'b0;
      if (wr_beat) f_pend[ram_wr_addr] <= 1'b1;
      if (m_axis_tvalid && m_axis_tready) f_out_pos <= f_out_pos + 1'b1;
      f_words_in  <= f_words_in + 8'(wr_beat);
      f_words_out <= f_words_out + 8'(rd_issue);
    end
  end
  always_comb if (f_past && !rst) begin
    if (wr_beat) assert (!f_pend[ram_wr_addr] || (rd_issue && ram_rd_addr == ram_wr_addr));
    if (rd_issue) assert (f_pend[ram_rd_addr]);
    if (wr_beat && rd_active_q) assert (wr_cnt_q < rd_cnt_q);
    assert (!(pending_q && rd_active_q));
    if (!rd_active_q) assert (rd_cnt_q == '0);
    if (rd_active_q) assert (rd_shift_q == wr_shift_q && wr_cnt_q <= rd_cnt_q);
    if (pending_q) assert (wr_cnt_q == '0);
    assert ({1'b0, wr_shift_q} < (SH_W+1)'(B) && {1'b0, rd_shift_q} < (SH_W+1)'(B));
    for (int j = 0; j < (1 << B); j++) begin
      assert (f_pend[rotl(B'(j), wr_shift_q)] ==
              (pending_q || (rd_active_q && B'(j) >= rd_cnt_q) || B'(j) < wr_cnt_q));
    end
    // words written - words read == words stored unread (no word created or lost)
    assert (8'(f_words_in - f_words_out) ==
            8'(wr_cnt_q) + (pending_q ? 8'(1 << B) : 8'd0) +
            (rd_active_q ? 8'(1 << B) - 8'(rd_cnt_q) : 8'd0));
`ifdef F_OUTPUT_FRAMING
    if (m_axis_tvalid) begin
      assert (m_axis_tlast == (f_out_pos[BD-1:0] == '1));
      assert (m_axis_tuser[0] == (f_out_pos == '0));
    end
`endif
  end
  always_comb if (f_past && !rst) begin
    cover (frames_out == 32'd2);
    cover (wr_beat && rd_active_q && wr_cnt_q == rd_cnt_q - 1'b1);  // writer right behind
    cover (m_axis_tvalid && m_axis_tlast && m_axis_tuser[0] == 1'b0 && !m_axis_tready);
  end
`endif

`ifdef FORMAL
  // (the FORMAL block above states this property for the proof)
`elsif SYNTHESIS
`else
  // block invariant (in place): never write a slot of the frame being read before reading it
  always_ff @(posedge clk) begin
    if (!rst && wr_beat && rd_active_q && (POW2 || READ_ORDER == 0))
      assert (wr_cnt_q < rd_cnt_q)
      else $error("corner_turn: writer overtook reader");
  end
`endif

endmodule

`default_nettype wire
