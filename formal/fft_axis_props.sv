// SPDX-License-Identifier: Apache-2.0
// Formal harness of fft_axis (formal/fft_axis.sby), N = 16, DATA_W = 8, GUARD_W = 0, no
// taper: both ports under the shared f_axis_port set (s_axis assumed, m_axis asserted: TVALID
// held until TREADY, payload stable while stalled; the block's own checkers say the same),
// and its port contract:
//   - no beat created: output beats <= input beats, and at most 4 frames in flight;
//   - output order: TUSER = output beat index mod N (bins in natural order), TLAST exactly on
//     bin N-1;
//   - the framing events: event_tlast_unexpected / _missing one cycle after an input beat
//     with TLAST set before position N-1 / clear at position N-1 (positions counted here from
//     the input beats), and never otherwise.
// Bound: the first output beat needs a whole frame in plus the pipeline (about 40 cycles),
// beyond the depth yices reaches here in minutes (20: 7 min); within the bound the input
// side, the advance copies through the first bubble (a frame's 16 samples in, then an empty
// input buffer: fft_axis' own cover reaches it at step 18, so the depth must stay above
// that for the bubble term of the advance to be checked), the framing
// events and the fft_reorder bank-reuse asserts (active inside) are checked, and the output
// assertions hold vacuously. The output port itself is fft_reorder's m_axis, proven
// unbounded in fft_reorder.sby (its covers reach output beats and TLAST).
// The cover task (depth 20) reaches input beats, both framing events and a bubble; the covers of a
// stalled input (the reorder buffer full) and fft_reorder's own covers need output beats and
// are removed from it (chformal): they are reached in fft_reorder.sby.
// The sby script cuts the stage data (butterfly sums, twiddle products, output rounding and
// their overflow flags) to free values: every property here is about control, and holds for
// any data, so the cut only removes the multipliers from the solver's work.
`default_nettype none

module fft_axis_props (
  input wire logic        clk,
  input wire logic        rst,
  input wire logic [15:0] s_axis_tdata,
  input wire logic        s_axis_tvalid,
  input wire logic        s_axis_tlast,
  input wire logic        m_axis_tready
);
  localparam int N = 16, LOG2N = 4, DATA_W = 8;
  logic             s_axis_tready, m_axis_tvalid, m_axis_tlast;
  logic [15:0]      m_axis_tdata;
  logic [LOG2N-1:0] m_axis_tuser;
  logic             ev_unexp, ev_miss, ev_ov;

  fft_axis #(.N(N), .NUM_CH(1), .DATA_W(DATA_W), .INVERSE(1'b0), .WINDOW(1'b0),
             .SCALE_SCH(32'hF), .GUARD_W(0)) dut (
    .clk, .rst, .s_axis_tdata, .s_axis_tvalid, .s_axis_tready, .s_axis_tlast,
    .m_axis_tdata, .m_axis_tvalid, .m_axis_tready, .m_axis_tlast, .m_axis_tuser,
    .event_tlast_unexpected(ev_unexp), .event_tlast_missing(ev_miss),
    .event_overflow(ev_ov));

  initial assume (rst);

  logic [7:0] n_in, n_out;
  f_axis_port #(.PAYLOAD_W(17), .ASSUME(1'b1), .COVER(1'b0)) u_s (
    .clk, .rst, .tvalid(s_axis_tvalid), .tready(s_axis_tready),
    .payload({s_axis_tlast, s_axis_tdata}), .beats(n_in));
  f_axis_port #(.PAYLOAD_W(16 + 1 + LOG2N), .COVER(1'b0)) u_m (
    .clk, .rst, .tvalid(m_axis_tvalid), .tready(m_axis_tready),
    .payload({m_axis_tuser, m_axis_tlast, m_axis_tdata}), .beats(n_out));

  logic past = 1'b0;
  logic unexp_q, miss_q;
  wire  in_beat = s_axis_tvalid && s_axis_tready;
  always_ff @(posedge clk) begin
    past    <= 1'b1;
    unexp_q <= !rst && in_beat && s_axis_tlast && n_in[LOG2N-1:0] != 4'(N - 1);
    miss_q  <= !rst && in_beat && !s_axis_tlast && n_in[LOG2N-1:0] == 4'(N - 1);
  end

  always_comb if (past && !rst) begin
    assert (8'(n_in - n_out) <= 8'(4 * N));
    assert (n_out <= n_in || n_in < 8'(4 * N));   // (8-bit counters: valid before the wrap)
    if (m_axis_tvalid) begin
      assert (n_out != n_in);
      assert (m_axis_tuser == n_out[LOG2N-1:0]);
      assert (m_axis_tlast == (m_axis_tuser == 4'(N - 1)));
    end
    assert (ev_unexp == unexp_q);
    assert (ev_miss == miss_q);
  end
  always_comb if (past && !rst) begin
    cover (in_beat && n_in == 8'd3);
    cover (ev_unexp);
    cover (ev_miss);
  end
  wire unused = ev_ov;
endmodule

`default_nettype wire
