// SPDX-License-Identifier: Apache-2.0
// Streaming FFT/IFFT with AXI4-Stream interfaces (open replacement of the Xilinx FFT IP):
// radix-2^2 single-path delay-feedback pipeline, one complex sample per clock per lane,
// continuous frames, natural-order output, full backpressure, self-draining.
//
// Zero fill (N_IN < N): a vector is N_IN input samples (TLAST on the last), windowed over
// their own count, then N - N_IN zeros the core inserts itself, one per clock, while
// s_axis_tready is low (the fill never waits for the input: N clocks per vector as without
// it). N_OUT < N: only bins 0..N_OUT-1 leave (TLAST on N_OUT-1), e.g. the positive half of
// the transform of real samples.
`default_nettype none

module fft_axis #(
  // Transform length in samples, power of two, 16..4096.
  parameter int N = 64,
  // Channels processed in parallel, one lane each, 1..16 (lane 0 in the LSBs).
  parameter int NUM_CH = 1,
  // Bits of I and of Q, input and output, 8..24.
  parameter int DATA_W = 16,
  // 0: forward DFT (e^-j); 1: inverse (e^+j), same scaling.
  parameter bit INVERSE = 0,
  // Input window applied before the first butterfly: 0 none, 1 periodic Hann.
  parameter bit WINDOW = 0,
  // Input samples per vector, 2..N (the rest of the N-point vector is zero-filled).
  parameter int N_IN = N,
  // Output bins per vector, 1..N: bins 0..N_OUT-1 in natural order.
  parameter int N_OUT = N,
  // Scaling schedule, bit s = 1 divides radix-2 stage s (s = 0 first) by 2 with convergent
  // rounding; bits >= log2(N) are ignored. Default 'hFFF (all stages): round(DFT(x)/N).
  parameter int unsigned SCALE_SCH = 32'hFFF,
  // Extra fraction bits carried inside the pipeline, 0..16; DATA_W+1+GUARD_W <= 27 so each
  // real multiplier fits one DSP48E2 (27 x 18).
  parameter int GUARD_W = 4,
  // Widest signed data operand of one twiddle multiplier, 8..27 (fft_twiddle): 27 the
  // DSP48E2 A port (one multiplier per real product), 18 an ECP5 MULT18X18D (wider operands
  // split in two registered partial products); same latency and bits.
  parameter int MUL_W = 27
) (
  // Clock and synchronous active-high reset.
  input  logic clk, rst,
  // AXI4-Stream sink: time-domain samples, {Q, I} per lane, tlast on sample N_IN-1.
  input  logic [NUM_CH*2*DATA_W-1:0] s_axis_tdata,
  input  logic s_axis_tvalid,
  output logic s_axis_tready,
  input  logic s_axis_tlast,
  // AXI4-Stream source: bins in natural order, tuser = bin index, tlast on bin N_OUT-1.
  output logic [NUM_CH*2*DATA_W-1:0] m_axis_tdata,
  output logic m_axis_tvalid,
  input  logic m_axis_tready,
  output logic m_axis_tlast,
  output logic [$clog2(N)-1:0] m_axis_tuser,
  // Events, one-cycle pulses, registered: tlast on a sample that is not N_IN-1 / missing on
  // sample N_IN-1 (the frame count is not resynchronised, like the Xilinx core); an output beat
  // whose computation saturated (any lane, any stage), the cycle after its handshake.
  output logic event_tlast_unexpected, event_tlast_missing, event_overflow
);

  localparam int LOG2N = $clog2(N);
  localparam int W     = DATA_W + 1 + GUARD_W;   // internal bits per component
  localparam int DW    = NUM_CH * 2 * W;
  localparam int ODW   = NUM_CH * 2 * DATA_W;
  localparam int CV_W  = fft_pkg::round_w(W, GUARD_W);   // the rounded output's bits
  localparam int CNT_W = LOG2N + 2;              // samples in flight < 4N

  // ---------------------------------------------------------------- parameter checks
  if (N < 16 || N > 4096 || (1 << LOG2N) != N) begin : g_bad_n
    $fatal(1, "%m: N=%0d must be a power of two in 16..4096", N);
  end
  if (N_IN < 2 || N_IN > N) begin : g_bad_n_in
    $fatal(1, "%m: N_IN=%0d not in 2..N (%0d)", N_IN, N);
  end
  if (N_OUT < 1 || N_OUT > N) begin : g_bad_n_out
    $fatal(1, "%m: N_OUT=%0d not in 1..N (%0d)", N_OUT, N);
  end
  if (NUM_CH < 1 || NUM_CH > 16) begin : g_bad_num_ch
    $fatal(1, "%m: NUM_CH=%0d must be in 1..16", NUM_CH);
  end
  if (DATA_W < 8 || DATA_W > 24) begin : g_bad_data_w
    $fatal(1, "%m: DATA_W=%0d must be in 8..24", DATA_W);
  end
  if (GUARD_W < 0 || GUARD_W > 16 || W > 27) begin : g_bad_guard_w
    $fatal(1, "%m: GUARD_W=%0d needs 0..16 and DATA_W+1+GUARD_W <= 27",
           GUARD_W);
  end

  // ---------------------------------------------------------------- input control
  // Stage boundary arrays: index s is the input of butterfly stage s, LOG2N the output.
  logic [DW-1:0]    st_data [LOG2N+1];
  logic             st_vld  [LOG2N+1];
  logic [LOG2N-1:0] st_pos  [LOG2N+1];
  logic             st_ov   [LOG2N+1];

  // The whole pipeline moves on the advance enable: a sample (from the input buffer or a fill
  // zero) enters, or a *bubble* when the buffer is empty at a frame boundary while valid
  // samples are still inside (self-draining). Bubbles carry a phantom index counting from 0 so
  // every stage keeps its frame alignment. Samples N_IN..N-1 of a vector are zeros (`fill`),
  // one per advance, the input held off.
  //
  // The advance is a register, decided a cycle ahead (issue 30: `adv` enables every pipeline
  // register, about 12 000 FF in the 4-lane N = 256 transform, so it must start at a flip-flop
  // placed beside its sinks, not at logic beside the control): adv_d is the advance condition
  //   can_adv && (buffer not empty || fill_q || bub_q),   can_adv = !cv_vld_q || wr_ok
  // evaluated on the next cycle's state (every term's next value from this cycle's registers,
  // the input handshake, this cycle's advance and the output handshake inside fft_reorder),
  // and registered in one copy per stage group (control, window, each butterfly, each
  // twiddle, output conversion, reorder), each `(* keep *)` so Yosys does not merge them.
  // formal/fft_axis.sby asserts every copy equal to the condition on the current state.
  // So the input needs a buffer whose TREADY is a register: two entries, s_axis_tready =
  // "an entry free and no fill" (the fill holds the input off exactly as before: N clocks a
  // vector, s_axis_tready low N - N_IN of them).
  // bub_q = (in_cnt_q == 0 && inflight_q != 0), kept a cycle ahead like the advance.
  logic [LOG2N-1:0] in_cnt_q, ph_cnt_q;
  logic [CNT_W-1:0] inflight_q;
  logic             bub_q, bub_d, bub_fire, bub_step;
  logic             fill_q, fill_d;
  logic             adv_c;       // the control's copy of the advance
  logic             adv_d;       // next cycle's advance
  logic             take, zero_fire, bubble;

  // input buffer: ib0_q the head, ib1_q the second entry
  logic [ODW-1:0]   ib0_q, ib1_q;
  logic [1:0]       ib_cnt_q, ib_cnt_d;
  logic             ib_rdy_q;    // s_axis_tready
  logic             s_fire, ib_ne, ib_pop;
  logic             smp_q;       // (ib_ne || fill_q): a sample enters on the next advance
  logic [LOG2N-1:0] s_cnt_q;     // position of the next input beat in its vector, 0..N_IN-1

  // last pipeline register (output conversion) and the reorder buffer write side
  logic [ODW:0]     cv_data_q;   // {overflow, data}
  logic [LOG2N-1:0] cv_pos_q;
  logic             cv_vld_q, cv_vld_d;
  logic             wr_ok_nxt;
  /* verilator lint_off UNUSEDSIGNAL */
  logic             wr_ok;       // this cycle's (the formal checks of adv_c only)
  /* verilator lint_on UNUSEDSIGNAL */
  logic             adv_o, adv_r;  // the output conversion's and the reorder's copies

  assign s_axis_tready = ib_rdy_q;
  assign s_fire        = s_axis_tvalid && ib_rdy_q;
  assign ib_ne         = ib_cnt_q != 2'd0;
  assign ib_pop        = adv_c && !fill_q && ib_ne;    // the buffer head enters stage 0
  assign zero_fire     = adv_c && fill_q;
  assign take          = ib_pop || zero_fire;          // a sample of a vector enters
  assign bubble        = adv_c && !fill_q && !ib_ne;   // (then bub_q is set)
  // bub_q's next value after a sample enters / a bubble (a sample leaves when cv_vld_q)
  assign bub_fire = in_cnt_q == LOG2N'(N - 1) && (!cv_vld_q || inflight_q != '0);
  assign bub_step = in_cnt_q == '0 && (cv_vld_q ? inflight_q != CNT_W'(1) : inflight_q != '0);

  // next cycle's state of the terms of the advance
  always_comb begin
    ib_cnt_d = ib_cnt_q + 2'(s_fire) - 2'(ib_pop);
    bub_d    = take ? bub_fire : (bubble ? bub_step : bub_q);
    fill_d   = fill_q;
    if (N_IN < N) begin
      if (ib_pop && in_cnt_q == LOG2N'(N_IN - 1)) fill_d = 1'b1;
      if (zero_fire && in_cnt_q == LOG2N'(N - 1)) fill_d = 1'b0;
    end
    cv_vld_d = adv_c ? st_vld[LOG2N] : cv_vld_q;
    adv_d    = (!cv_vld_d || wr_ok_nxt) && (ib_cnt_d != 2'd0 || fill_d || bub_d);
  end

  // the control's copy of the advance and the buffer's ready
  (* keep *) always_ff @(posedge clk) begin
    if (rst) begin
      adv_c    <= 1'b0;
      ib_rdy_q <= 1'b1;
    end else begin
      adv_c    <= adv_d;
      ib_rdy_q <= ib_cnt_d != 2'd2 && !fill_d;
    end
  end
  // the window's select of the position and valid, a register (timing: the buffer count's
  // compare is not ahead of the window's coefficient ROM)
  always_ff @(posedge clk) begin
    if (rst) begin
      smp_q <= 1'b0;
    end else begin
      smp_q <= ib_cnt_d != 2'd0 || fill_d;
    end
  end

  always_ff @(posedge clk) begin
    if (rst) begin
      in_cnt_q   <= '0;
      ph_cnt_q   <= '0;
      inflight_q <= '0;
      fill_q     <= 1'b0;
      bub_q      <= 1'b0;
      ib_cnt_q   <= '0;
      s_cnt_q    <= '0;
    end else begin
      bub_q    <= bub_d;
      fill_q   <= fill_d;
      ib_cnt_q <= ib_cnt_d;
      if (take) begin
        in_cnt_q <= in_cnt_q + 1'b1;
        ph_cnt_q <= '0;
      end else if (bubble) begin
        ph_cnt_q <= ph_cnt_q + 1'b1;
      end
      if (s_fire) s_cnt_q <= (s_cnt_q == LOG2N'(N_IN - 1)) ? '0 : s_cnt_q + 1'b1;
      inflight_q <= inflight_q + CNT_W'(take) - CNT_W'(adv_c && cv_vld_q);
    end
  end

  // buffer data (not reset): a beat goes to the head when the buffer is empty or the head
  // leaves, else behind it; s_axis_tready is low with both entries taken
  always_ff @(posedge clk) begin
    if (s_fire && (ib_cnt_q == 2'd0 || (ib_cnt_q == 2'd1 && ib_pop))) ib0_q <= s_axis_tdata;
    else if (ib_pop)                                                   ib0_q <= ib1_q;
    if (s_fire) ib1_q <= s_axis_tdata;
  end

  // ---------------------------------------------------------------- input / window stage
  // the window's copy of the advance
  logic adv_w;
  (* keep *) always_ff @(posedge clk) adv_w <= !rst && adv_d;

  fft_window #(
    .NUM_CH(NUM_CH), .DATA_W(DATA_W), .GUARD_W(GUARD_W), .W(W), .LOG2N(LOG2N),
    .WINDOW(WINDOW), .N_IN(N_IN)
  ) u_window (
    .clk, .rst, .en(adv_w),
    // (the window reads in_vld and in_pos only when it advances, and then a sample enters
    // exactly when the buffer holds one or a fill zero is due: both from registers)
    .in_data(fill_q ? '0 : ib0_q), .in_vld(smp_q),
    .in_pos(smp_q ? in_cnt_q : ph_cnt_q),
    .out_data(st_data[0]), .out_vld(st_vld[0]), .out_pos(st_pos[0])
  );
  assign st_ov[0] = 1'b0;

  // ---------------------------------------------------------------- SDF stages
  for (genvar s = 0; s < LOG2N; s++) begin : g_stage
    logic [DW-1:0]    bo_data;
    logic             bo_vld, bo_ov;
    logic [LOG2N-1:0] bo_pos, bo_pos_ahead;
    logic             adv_bf;   // this butterfly's copy of the advance

    (* keep *) always_ff @(posedge clk) adv_bf <= !rst && adv_d;

    fft_sdf_bf #(
      .NUM_CH(NUM_CH), .W(W), .LOG2N(LOG2N), .D(N >> (s + 1)),
      .ROTATE(s % 2 == 1), .INVERSE(INVERSE), .SCALE(SCALE_SCH[s])
    ) u_bf (
      .clk, .rst, .en(adv_bf),
      .in_data(st_data[s]), .in_vld(st_vld[s]), .in_pos(st_pos[s]), .in_ov(st_ov[s]),
      .out_data(bo_data), .out_vld(bo_vld), .out_pos(bo_pos), .out_ov(bo_ov),
      .out_pos_ahead(bo_pos_ahead)
    );

    if (s % 2 == 1 && s + 1 < LOG2N) begin : g_tw
      // twiddle after the radix-2^2 pair (s-1, s), sub-transform length N >> (s-1)
      logic adv_tw;   // this twiddle's copy of the advance
      (* keep *) always_ff @(posedge clk) adv_tw <= !rst && adv_d;

      fft_twiddle #(
        .NUM_CH(NUM_CH), .W(W), .LOG2N(LOG2N), .LOG2M(LOG2N - s + 1), .INVERSE(INVERSE),
        .MUL_W(MUL_W)
      ) u_tw (
        .clk, .rst, .en(adv_tw),
        .in_data(bo_data), .in_vld(bo_vld), .in_pos(bo_pos), .in_ov(bo_ov),
        .in_pos_ahead(bo_pos_ahead),
        .out_data(st_data[s+1]), .out_vld(st_vld[s+1]), .out_pos(st_pos[s+1]),
        .out_ov(st_ov[s+1])
      );
    end else begin : g_notw
      assign st_data[s+1] = bo_data;
      assign st_vld[s+1]  = bo_vld;
      assign st_pos[s+1]  = bo_pos;
      assign st_ov[s+1]   = bo_ov;
      /* verilator lint_off UNUSEDSIGNAL */
      logic unused_ahead;   // only a twiddle looks ahead
      assign unused_ahead = ^bo_pos_ahead;
      /* verilator lint_on UNUSEDSIGNAL */
    end
  end

  // ---------------------------------------------------------------- output conversion
  logic [ODW-1:0] cv_d;
  logic           cv_ov;
  always_comb begin
    logic signed [63:0] v;
    cv_d  = '0;
    cv_ov = st_ov[LOG2N];
    for (int c = 0; c < 2 * NUM_CH; c++) begin
      v = fft_pkg::round_conv(64'(signed'(st_data[LOG2N][c*W +: W])), GUARD_W);
      cv_ov = cv_ov | fft_pkg::sat_ov(v, DATA_W, CV_W);
      cv_d[c*DATA_W +: DATA_W] = DATA_W'(fft_pkg::sat_val(v, DATA_W, CV_W));
    end
  end

  (* keep *) always_ff @(posedge clk) adv_o <= !rst && adv_d;

  always_ff @(posedge clk) begin
    if (adv_o) begin
      cv_data_q <= {cv_ov, cv_d};
      cv_pos_q  <= st_pos[LOG2N];
    end
  end

  always_ff @(posedge clk) begin
    if (rst) begin
      cv_vld_q <= 1'b0;
    end else if (adv_o) begin
      cv_vld_q <= st_vld[LOG2N];
    end
  end

  // ---------------------------------------------------------------- reorder + output
  logic [ODW:0] m_word;

  (* keep *) always_ff @(posedge clk) adv_r <= !rst && adv_d;

  fft_reorder #(.N(N), .WIDTH(ODW + 1), .N_OUT(N_OUT)) u_reorder (
    .clk, .rst,
    .wr_en(adv_r && cv_vld_q), .wr_pos(cv_pos_q), .wr_step(adv_r), .wr_pos_nxt(st_pos[LOG2N]),
    .wr_data(cv_data_q), .wr_ok, .wr_ok_nxt,
    .m_axis_tdata(m_word), .m_axis_tvalid(m_axis_tvalid), .m_axis_tready(m_axis_tready),
    .m_axis_tlast(m_axis_tlast), .m_axis_tuser(m_axis_tuser)
  );
  assign m_axis_tdata = m_word[ODW-1:0];

  // ---------------------------------------------------------------- events
  logic ev_unexp_q, ev_miss_q, ev_ov_q;
  always_ff @(posedge clk) begin
    if (rst) begin
      ev_unexp_q <= 1'b0;
      ev_miss_q  <= 1'b0;
      ev_ov_q    <= 1'b0;
    end else begin
      ev_unexp_q <= s_fire && s_axis_tlast && s_cnt_q != LOG2N'(N_IN - 1);
      ev_miss_q  <= s_fire && !s_axis_tlast && s_cnt_q == LOG2N'(N_IN - 1);
      ev_ov_q    <= m_axis_tvalid && m_axis_tready && m_word[ODW];
    end
  end
  assign event_tlast_unexpected = ev_unexp_q;
  assign event_tlast_missing    = ev_miss_q;
  assign event_overflow         = ev_ov_q;

  // ---------------------------------------------------------------- protocol checks
`ifdef FORMAL
  // the look-ahead registers (formal/fft_axis.sby): the bubble flag, the advance and its
  // copies equal the conditions they replace on the current state; the input buffer
  logic f_past = 1'b0;
  always_ff @(posedge clk) f_past <= 1'b1;
  always_comb if (f_past && !rst) begin
    assert (bub_q == (in_cnt_q == '0 && inflight_q != '0));
    assert (adv_c == ((!cv_vld_q || wr_ok) && (ib_ne || fill_q || bub_q)));
    assert (adv_w == adv_c && adv_o == adv_c && adv_r == adv_c);
    assert (ib_cnt_q <= 2'd2);
    assert (s_axis_tready == (ib_cnt_q != 2'd2 && !fill_q));
    assert (smp_q == (ib_ne || fill_q));
    if (bubble) assert (bub_q);
    cover (bubble);   // first reached at step 18 (N = 16): the bmc depth must exceed it
  end
  for (genvar s = 0; s < LOG2N; s++) begin : g_f_adv
    always_comb if (f_past && !rst) assert (g_stage[s].adv_bf == adv_c);
    if (s % 2 == 1 && s + 1 < LOG2N) begin : g_f_tw
      always_comb if (f_past && !rst) assert (g_stage[s].g_tw.adv_tw == adv_c);
    end
  end
`endif

  // AXI4-Stream protocol on every port (rtl/common/axis_checker.sv)
  axis_checker #(.PAYLOAD_W(ODW + 1), .ASSUME(1'b1)) u_chk_s_axis (
    .clk, .rst, .tvalid(s_axis_tvalid), .tready(s_axis_tready),
    .payload({s_axis_tlast, s_axis_tdata}));
  axis_checker #(.PAYLOAD_W(ODW + 1 + LOG2N)) u_chk_m_axis (
    .clk, .rst, .tvalid(m_axis_tvalid), .tready(m_axis_tready),
    .payload({m_axis_tuser, m_axis_tlast, m_axis_tdata}));
endmodule

`default_nettype wire
