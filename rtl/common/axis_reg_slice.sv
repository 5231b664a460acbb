// SPDX-License-Identifier: Apache-2.0
// AXI4-Stream register slice (a two-entry skid buffer): every output (m_axis_* and
// s_axis_tready) comes straight from a register, so no combinational path crosses it in
// either direction. Full throughput (one beat per clock with the sink always ready),
// latency one clock, nothing dropped, duplicated or reordered.
//
// Use it where a handshake runs between blocks that the placer puts far apart: the slice
// cuts TVALID -> TREADY loops and long TREADY fan-outs into two register-to-register hops
// (docs/buffers.md 9; in radar_pipeline between frame_align and the range FFT, and in front
// of the packetizer, docs/synth.md note 20).
//
// State: the output register (out_valid_q, out_q) and the skid register (skid_valid_q,
// skid_q), which catches the one beat accepted in the clock the sink stalls. TREADY is
// !skid_valid_q, low in reset (a beat offered during reset is not taken, and so not lost).
// Model: model/axis_reg_slice.py (cycle-accurate).
`default_nettype none

module axis_reg_slice #(
  // Bits of TDATA, 1..4096.
  parameter int DATA_W = 32,
  // Bits of TUSER, 1..256 (tie the input to 0 when the stream has none).
  parameter int USER_W = 1
) (
  input  wire logic              clk,
  input  wire logic              rst,
  input  wire logic [DATA_W-1:0] s_axis_tdata,
  input  wire logic              s_axis_tvalid,
  output logic                   s_axis_tready,
  input  wire logic              s_axis_tlast,
  input  wire logic [USER_W-1:0] s_axis_tuser,
  output logic      [DATA_W-1:0] m_axis_tdata,
  output logic                   m_axis_tvalid,
  input  wire logic              m_axis_tready,
  output logic                   m_axis_tlast,
  output logic      [USER_W-1:0] m_axis_tuser
);

  if (DATA_W < 1 || DATA_W > 4096) begin : g_bad_data_w
    $fatal(1, "%m: DATA_W=%0d not in 1..4096", DATA_W);
  end
  if (USER_W < 1 || USER_W > 256) begin : g_bad_user_w
    $fatal(1, "%m: USER_W=%0d not in 1..256", USER_W);
  end

  localparam int PW = USER_W + 1 + DATA_W;  // {tuser, tlast, tdata}

  logic          out_valid_q, skid_valid_q;
  logic [PW-1:0] out_q, skid_q;
  logic [PW-1:0] s_payload;
  logic          out_free, in_beat;

  assign s_payload     = {s_axis_tuser, s_axis_tlast, s_axis_tdata};
  assign s_axis_tready = !rst && !skid_valid_q;
  assign in_beat       = s_axis_tvalid && s_axis_tready;
  // the output register takes a new word at this edge: empty, or its word leaves now
  assign out_free      = !out_valid_q || m_axis_tready;

  always_ff @(posedge clk) begin
    if (rst) begin
      out_valid_q  <= 1'b0;
      skid_valid_q <= 1'b0;
    end else if (out_free) begin
      // the skid's word first (TREADY was low, so no input beat this clock), else the input
      out_valid_q  <= skid_valid_q || in_beat;
      skid_valid_q <= 1'b0;
    end else if (in_beat) begin
      skid_valid_q <= 1'b1;  // the sink stalled in the clock a beat came in
    end
  end

  // Payload registers (no reset: only read with their valid bit)
  always_ff @(posedge clk) begin
    if (out_free) out_q <= skid_valid_q ? skid_q : s_payload;
    if (!out_free && in_beat) skid_q <= s_payload;
  end

  assign m_axis_tvalid = out_valid_q;
  assign {m_axis_tuser, m_axis_tlast, m_axis_tdata} = out_q;

`ifdef FORMAL
  // Formal properties (formal/axis_reg_slice.sby). The slice is a FIFO of depth 2 whose
  // TREADY is "not full": beats in minus beats out is its occupancy, 0..2, and TREADY is
  // low exactly when it is 2. A beat chosen by the solver (input index f_pick) leaves at the
  // same output index with the same payload: nothing dropped, duplicated, reordered or
  // altered.
  logic        f_past = 1'b0;
  logic [7:0]  f_in_n = '0, f_out_n = '0;     // beats since reset (wrap unreachable in depth)
  (* anyconst *) logic [7:0] f_pick;
  logic [PW-1:0] f_pick_data;
  logic          f_pick_seen = 1'b0;
  logic          out_beat;
  assign out_beat = m_axis_tvalid && m_axis_tready;
  initial assume (rst);
  always_ff @(posedge clk) begin
    f_past <= 1'b1;
    if (rst) begin
      f_in_n      <= '0;
      f_out_n     <= '0;
      f_pick_seen <= 1'b0;
    end else begin
      if (in_beat) f_in_n <= f_in_n + 1'b1;
      if (out_beat) f_out_n <= f_out_n + 1'b1;
      if (in_beat && f_in_n == f_pick) begin
        f_pick_seen <= 1'b1;
        f_pick_data <= s_payload;
      end
    end
  end
  always_comb if (f_past && !rst) begin
    assume (f_in_n != '1);
    assert (f_in_n - f_out_n == 8'(out_valid_q) + 8'(skid_valid_q));
    assert (f_out_n <= f_in_n);
    assert (!skid_valid_q || out_valid_q);        // the skid fills only behind a full output
    assert (f_pick_seen == (f_in_n > f_pick));
    assert (s_axis_tready == !skid_valid_q);
    if (out_beat && f_out_n == f_pick) assert (f_pick_seen && m_axis_tdata == f_pick_data[DATA_W-1:0]
                                              && {m_axis_tuser, m_axis_tlast} ==
                                                 f_pick_data[PW-1:DATA_W]);
    // the word the pick lives in while it waits: in the output behind nothing, or the skid
    if (f_pick_seen && f_out_n <= f_pick) begin
      if (f_out_n == f_pick) assert (out_valid_q && out_q == f_pick_data);
      else assert (skid_valid_q && skid_q == f_pick_data);
    end
  end
  always_comb if (f_past && !rst) begin
    cover (in_beat && out_beat && skid_valid_q == 1'b0 && out_valid_q);  // full rate
    cover (skid_valid_q && out_beat);                                     // skid drains
    cover (f_out_n == 8'd4 && f_in_n == 8'd6);
  end
`endif

  // AXI4-Stream protocol on both ports (rtl/common/axis_checker.sv)
  axis_checker #(.PAYLOAD_W(PW), .ASSUME(1'b1)) u_chk_s_axis (
    .clk, .rst, .tvalid(s_axis_tvalid), .tready(s_axis_tready), .payload(s_payload));
  axis_checker #(.PAYLOAD_W(PW)) u_chk_m_axis (
    .clk, .rst, .tvalid(m_axis_tvalid), .tready(m_axis_tready), .payload(out_q));

endmodule

`default_nettype wire
