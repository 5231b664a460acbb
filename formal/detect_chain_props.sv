// SPDX-License-Identifier: Apache-2.0
// Formal harness of detect_chain (formal/detect_chain.sby): nci -> cfar_2d -> detect_records
// with 1 TX x 2 RX, 4 x 4 cells, guard 0, training 1, 4-bit scales (any constant),
// MAX_DETECTIONS 1 (9-word record frames). Both ports under the shared f_axis_port set, and:
//   - fixed frame length: TLAST exactly on every 9th output word;
//   - frame_count == record frames out on m_axis (or one more while its closing words wait
//     in the output FIFO), frames out never more than the input frames;
//   - status_framing_error is exactly "some input TLAST not on Doppler bin 3".
// Bound: a record frame leaves only after the whole 4 x 4 map and the CFAR's last passes
// (beyond the depth reached here, 16): the bmc checks the input side, the framing flag and
// every internal port and FIFO invariant of nci/cfar_2d/detect_records within the bound;
// the output assertions hold vacuously (detect_records.sby reaches record frames). The
// cover task (18) keeps the covers the bound can reach (input beats, the framing flag).
`default_nettype none

module detect_chain_props (
  input wire logic        clk,
  input wire logic        rst,
  input wire logic [63:0] s_axis_tdata,
  input wire logic        s_axis_tvalid,
  input wire logic        s_axis_tlast,
  input wire logic        m_axis_tready
);
  localparam int FW = 17;  // MAX_DETECTIONS * (HDR 8 + TX 1) + HDR 8
  (* anyconst *) logic [11:0] cfg_scale;
  (* anyconst *) logic [1:0] cfg_kind;       // any kind (OS not built: KIND)
  (* anyconst *) logic       cfg_local_max;
  logic        s_axis_tready, m_axis_tvalid, m_axis_tlast, framing, trunc;
  logic [63:0] m_axis_tdata;
  logic [31:0] detection_count, frame_count;

  detect_chain #(.NUM_TX(1), .NUM_RX(2), .N_RANGE(4), .N_DOPPLER(4), .GUARD_R(0),
                 .GUARD_D(0), .TRAIN_R(1), .TRAIN_D(1), .KIND(0), .SCALE_W(4),
                 .SCALE_FRAC(1), .MAX_DETECTIONS(1)) dut (
    .clk, .rst, .cfg_scale, .cfg_kind, .cfg_local_max, .cfg_max_detections(16'd1),
    .frame_start(),
    .s_axis_tdata, .s_axis_tvalid, .s_axis_tready, .s_axis_tlast,
    .m_axis_tdata, .m_axis_tvalid, .m_axis_tready, .m_axis_tlast,
    .status_framing_error(framing), .status_truncated(trunc), .detection_count,
    .frame_count);

  initial assume (rst);

  logic [7:0] n_in, n_out;
  f_axis_port #(.PAYLOAD_W(65), .ASSUME(1'b1)) u_s (
    .clk, .rst, .tvalid(s_axis_tvalid), .tready(s_axis_tready),
    .payload({s_axis_tlast, s_axis_tdata}), .beats(n_in));
  f_axis_port #(.PAYLOAD_W(65), .COVER(1'b0)) u_m (
    .clk, .rst, .tvalid(m_axis_tvalid), .tready(m_axis_tready),
    .payload({m_axis_tlast, m_axis_tdata}), .beats(n_out));

  logic       past = 1'b0;
  logic [4:0] pos_q;
  logic [7:0] n_frames;
  logic       f_err;
  always_ff @(posedge clk) begin
    past <= 1'b1;
    if (rst) begin
      pos_q    <= '0;
      n_frames <= '0;
      f_err    <= 1'b0;
    end else begin
      if (m_axis_tvalid && m_axis_tready) begin
        pos_q <= (pos_q == 5'(FW - 1)) ? '0 : pos_q + 5'd1;
        if (m_axis_tlast) n_frames <= n_frames + 8'd1;
      end
      if (s_axis_tvalid && s_axis_tready && s_axis_tlast != (n_in[1:0] == 2'd3)) f_err <= 1'b1;
    end
  end
  always_comb if (past && !rst) begin
    if (m_axis_tvalid) assert (m_axis_tlast == (pos_q == 5'(FW - 1)));
    // frame_count: frames whose last word was issued into the 4-word output FIFO, so at
    // most one closed frame has not yet left m_axis
    assert (n_frames <= frame_count[7:0] && frame_count[7:0] <= n_frames + 8'd1);
    if (frame_count[7:0] != n_frames) assert (m_axis_tvalid);
    assert ({n_frames, 4'd0} <= 12'(n_in));
    assert (framing == f_err);
  end
  always_comb if (past && !rst) begin
    cover (framing);
  end
  wire unused = ^{trunc, detection_count};
endmodule

`default_nettype wire
