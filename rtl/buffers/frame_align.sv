// SPDX-License-Identifier: Apache-2.0
// Keeps the chirp stream frame-aligned after the ADC ping-pong lost chirps: the rest of a
// damaged frame is zero-filled (so the corner turn always receives whole frames) and input
// is discarded until the next frame start; every frame is reported as clean or damaged.
//
// Input: whole chirps from chirp_pingpong (TLAST on sample N_RANGE-1; on a chirp's first
// sample TUSER[0] = frame start, TUSER[1] = chirps were discarded before this one).
// A frame is FRAME_CHIRPS chirps. Rules, checked on the first sample of every input chirp:
//   - frame start while the current frame is incomplete: zero-fill the current frame, then
//     take this chirp as chirp 0 of the next (framing error);
//   - discontinuity (TUSER[1]): zero-fill the current frame if it has begun, then discard
//     chirps until a frame start (the lost chirps' frame cannot be trusted);
//   - a chirp without frame start where a frame must begin: discard it (after reset the
//     ADC may be mid-frame).
// Zero-filled frames are flagged on frame_done_damaged; nothing is lost silently.
`default_nettype none

module frame_align #(
  // Receive lanes per word, 1..64.
  parameter int NUM_RX = 4,
  // Bits of I and of Q, 8..32.
  parameter int DATA_W = 16,
  // Samples per chirp, 2..65536.
  parameter int N_RANGE = 64,
  // Chirps per frame (NUM_TX * N_DOPPLER), 1..2^24.
  parameter int FRAME_CHIRPS = 256
) (
  input  wire logic                       clk,
  input  wire logic                       rst,
  // Chirps from the ping-pong
  input  wire logic [NUM_RX*2*DATA_W-1:0] s_axis_tdata,
  input  wire logic                       s_axis_tvalid,
  output logic                            s_axis_tready,
  input  wire logic                       s_axis_tlast,
  input  wire logic [1:0]                 s_axis_tuser,
  // Whole frames of whole chirps to the range FFT (TLAST on every chirp's last sample)
  output logic      [NUM_RX*2*DATA_W-1:0] m_axis_tdata,
  output logic                            m_axis_tvalid,
  input  wire logic                       m_axis_tready,
  output logic                            m_axis_tlast,
  // One pulse per output frame, with whether any of its chirps were zero-filled
  output logic                            frame_done,
  output logic                            frame_done_damaged,
  // Status (cleared only by rst)
  output logic      [31:0]                frames_damaged,    // frames with zero-filled chirps
  output logic      [31:0]                chirps_filled,     // zero chirps inserted
  output logic      [31:0]                chirps_discarded   // input chirps thrown away
);

  localparam int WORD_W = NUM_RX * 2 * DATA_W;
  localparam int SMP_W  = (N_RANGE > 1) ? $clog2(N_RANGE) : 1;
  localparam int CHP_W  = (FRAME_CHIRPS > 1) ? $clog2(FRAME_CHIRPS) : 1;

  if (NUM_RX < 1 || NUM_RX > 64) begin : g_bad_num_rx
    $fatal(1, "%m: NUM_RX=%0d not in 1..64", NUM_RX);
  end
  if (N_RANGE < 2 || N_RANGE > 65536) begin : g_bad_n_range
    $fatal(1, "%m: N_RANGE=%0d not in 2..65536", N_RANGE);
  end
  if (FRAME_CHIRPS < 1 || FRAME_CHIRPS > (1 << 24)) begin : g_bad_frame_chirps
    $fatal(1, "%m: FRAME_CHIRPS=%0d not in 1..2^24", FRAME_CHIRPS);
  end

  typedef enum logic [1:0] {PASS, FILL, DISCARD} state_t;
  state_t           state_q;
  logic [SMP_W-1:0] smp_q;        // sample index within the chirp being emitted
  logic [CHP_W-1:0] chirp_q;      // chirps emitted in the current frame
  logic             in_first_q;   // next input beat is the first sample of a chirp
  logic             discard_q;    // after the fill, discard input up to a frame start
  // Look-ahead flags, each updated with the counter it stands for (formal: equal to its
  // compare), so the handshake decisions start one register away instead of behind a compare
  logic             smp_last_q;   // smp_q == N_RANGE - 1
  logic             chirp_last_q; // chirp_q == FRAME_CHIRPS - 1
  logic             begun_q;      // chirp_q != 0
  logic [31:0]      dmg_cnt_q, fill_cnt_q, disc_cnt_q;

  // Decisions on the first sample of an input chirp
  logic sof, gap, frame_begun, at_first, need_fill, need_discard, disc_stop;
  assign sof          = s_axis_tuser[0];
  assign gap          = s_axis_tuser[1];
  assign frame_begun  = begun_q;
  assign at_first     = s_axis_tvalid && in_first_q;
  // chirps of the current frame were lost (gap) or its end never came (early frame start),
  // or the frame's start chirp itself was lost: fill up with zeros so nothing goes missing
  assign need_fill    = at_first && ((frame_begun && (sof || gap)) || (!frame_begun && gap &&
                                                                          !sof));
  // a chirp that cannot start a frame (e.g. the ADC was mid-frame at reset)
  assign need_discard = at_first && !frame_begun && !sof && !gap;
  assign disc_stop    = at_first && sof;

  logic chirp_end, frame_end;
  assign chirp_end = smp_last_q;
  assign frame_end = smp_last_q && chirp_last_q;

  always_comb begin
    s_axis_tready = 1'b0;
    m_axis_tvalid = 1'b0;
    m_axis_tdata  = s_axis_tdata;
    m_axis_tlast  = chirp_end;
    unique case (state_q)
      PASS: begin
        s_axis_tready = !(need_fill || need_discard) && m_axis_tready;
        m_axis_tvalid = !(need_fill || need_discard) && s_axis_tvalid;
      end
      FILL: begin
        m_axis_tvalid = 1'b1;
        m_axis_tdata  = '0;
      end
      DISCARD: s_axis_tready = !disc_stop;  // the frame-start chirp itself is kept
      default: ;
    endcase
  end

  logic out_beat, in_beat;
  assign out_beat = m_axis_tvalid && m_axis_tready;
  assign in_beat  = s_axis_tvalid && s_axis_tready;

  assign frame_done         = out_beat && frame_end;
  assign frame_done_damaged = state_q == FILL;  // a fill always runs to the frame's end

  always_ff @(posedge clk) begin
    if (rst) begin
      state_q      <= PASS;
      smp_q        <= '0;
      chirp_q      <= '0;
      smp_last_q   <= 1'b0;  // N_RANGE >= 2
      chirp_last_q <= FRAME_CHIRPS == 1;
      begun_q      <= 1'b0;
      in_first_q   <= 1'b1;
      discard_q    <= 1'b0;
      dmg_cnt_q    <= '0;
      fill_cnt_q   <= '0;
      disc_cnt_q   <= '0;
    end else begin
      if (in_beat) in_first_q <= s_axis_tlast;
      unique case (state_q)
        PASS: begin
          if (need_fill) begin
            state_q   <= FILL;             // the held chirp is looked at again afterwards
            discard_q <= gap && !sof;
          end else if (need_discard) begin
            state_q <= DISCARD;
          end
        end
        FILL: begin  // m_axis_tvalid is high throughout: a beat is m_axis_tready
          if (m_axis_tready && chirp_end && fill_cnt_q != '1) fill_cnt_q <= fill_cnt_q + 32'd1;
          if (m_axis_tready && frame_end) begin
            state_q <= discard_q ? DISCARD : PASS;
            if (dmg_cnt_q != '1) dmg_cnt_q <= dmg_cnt_q + 32'd1;
          end
        end
        DISCARD: begin
          if (disc_stop) state_q <= PASS;
          else if (in_beat && s_axis_tlast && disc_cnt_q != '1) disc_cnt_q <= disc_cnt_q + 32'd1;
        end
        default: state_q <= PASS;
      endcase
      if (out_beat) begin
        smp_q      <= chirp_end ? '0 : smp_q + 1'b1;
        smp_last_q <= smp_q == SMP_W'(N_RANGE - 2);  // (false at a chirp's end)
        if (chirp_end) begin
          chirp_q      <= frame_end ? '0 : chirp_q + 1'b1;
          chirp_last_q <= FRAME_CHIRPS == 1 || chirp_q == CHP_W'(FRAME_CHIRPS - 2);
          begun_q      <= !frame_end;
        end
      end
    end
  end

  assign frames_damaged   = dmg_cnt_q;
  assign chirps_filled    = fill_cnt_q;
  assign chirps_discarded = disc_cnt_q;

`ifdef FORMAL
  // Formal properties (formal/frame_align.sby). Output framing: every output chirp is
  // N_RANGE words with TLAST on the last, every output frame FRAME_CHIRPS chirps; PASS moves
  // beats 1:1 (none created or lost), FILL emits zeros only and runs to the frame's end,
  // DISCARD emits nothing; the fill, damage and discard counters count exactly those events.
  logic        f_past = 1'b0;
  logic [31:0] f_fill_chirps = '0, f_dmg_frames = '0, f_disc_chirps = '0;
  logic [SMP_W-1:0] f_in_pos = '0;  // input sample index: the input contract is whole chirps
  initial assume (rst);
  always_comb if (!rst && s_axis_tvalid) assume (s_axis_tlast == (f_in_pos == SMP_W'(N_RANGE - 1)));
  always_ff @(posedge clk) begin
    f_past <= 1'b1;
    if (rst) f_in_pos <= '0;
    else if (in_beat) f_in_pos <= s_axis_tlast ? '0 : f_in_pos + 1'b1;
    if (rst) begin
      f_fill_chirps <= '0;
      f_dmg_frames  <= '0;
      f_disc_chirps <= '0;
    end else begin
      if (state_q == FILL && out_beat && chirp_end) f_fill_chirps <= f_fill_chirps + 1;
      if (frame_done && frame_done_damaged) f_dmg_frames <= f_dmg_frames + 1;
      if (state_q == DISCARD && in_beat && s_axis_tlast) f_disc_chirps <= f_disc_chirps + 1;
    end
  end
  always_comb if (f_past && !rst) begin
    assume (f_fill_chirps != '1 && f_disc_chirps != '1 && f_dmg_frames != '1);  // no saturation
    assert (state_q == PASS || state_q == FILL || state_q == DISCARD);
    assert (smp_q <= SMP_W'(N_RANGE - 1));
    assert (chirp_q <= CHP_W'(FRAME_CHIRPS - 1));
    assert (m_axis_tlast == (smp_q == SMP_W'(N_RANGE - 1)));
    assert (smp_last_q == (smp_q == SMP_W'(N_RANGE - 1)));
    assert (chirp_last_q == (chirp_q == CHP_W'(FRAME_CHIRPS - 1)));
    assert (begun_q == (chirp_q != '0));
    if (state_q == PASS) assert (in_beat == out_beat);
    if (state_q == FILL) assert (m_axis_tvalid && m_axis_tdata == '0 && !s_axis_tready);
    if (state_q == DISCARD) assert (!m_axis_tvalid);
    // input and output chirps stay aligned: PASS forwards whole chirps
    assert (f_in_pos <= SMP_W'(N_RANGE - 1));
    assert (in_first_q == (f_in_pos == '0));
    if (state_q == PASS) assert (smp_q == f_in_pos);
    if (state_q == FILL) assert (in_first_q);
    if (state_q == DISCARD) assert (smp_q == '0 && chirp_q == '0);
    // a clean frame start where no frame has begun is forwarded: no fill, no discard
    if (state_q == PASS && at_first && sof && !gap && !frame_begun)
      assert (!need_fill && !need_discard);
    // a clean chirp inside a begun frame is forwarded too
    if (state_q == PASS && at_first && !sof && !gap && frame_begun)
      assert (!need_fill && !need_discard);
    assert (fill_cnt_q == f_fill_chirps);
    assert (dmg_cnt_q == f_dmg_frames);
    assert (disc_cnt_q == f_disc_chirps);
  end
  always_ff @(posedge clk) if (f_past && !$past(rst) && !rst) begin
    // a fill runs to the end of its frame
    if ($past(state_q == FILL) && !$past(out_beat && frame_end)) assert (state_q == FILL);
  end
  always_comb if (f_past && !rst) begin
    cover (frame_done && !frame_done_damaged);
    cover (frame_done && frame_done_damaged && discard_q);
    cover (state_q == DISCARD && disc_stop);
    cover (chirps_discarded == 32'd1 && frames_damaged == 32'd1 && frame_done);
  end
`endif

  // AXI4-Stream protocol on every port (rtl/common/axis_checker.sv)
  axis_checker #(.PAYLOAD_W(WORD_W + 3), .ASSUME(1'b1)) u_chk_s_axis (
    .clk, .rst, .tvalid(s_axis_tvalid), .tready(s_axis_tready),
    .payload({s_axis_tuser, s_axis_tlast, s_axis_tdata}));
  axis_checker #(.PAYLOAD_W(WORD_W + 1)) u_chk_m_axis (
    .clk, .rst, .tvalid(m_axis_tvalid), .tready(m_axis_tready),
    .payload({m_axis_tlast, m_axis_tdata}));

endmodule

`default_nettype wire
