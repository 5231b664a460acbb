// SPDX-License-Identifier: Apache-2.0
// Formal harness of detect_records (formal/detect_records.sby): 1 TX x 4 RX, 4 x 4 cells,
// POW_W 8, SUM_W 12, CNT_W 4 (32-bit cells), SNAP_ROWS 4, MAX_DETECTIONS 1 (5-word record
// frames: 2 header words + 1 snapshot word + ... + the trailer, padded). The cell stream is
// what cfar_2d sends (tuser {r, d}, rows starting at d = 1); the snapshot writer writes only
// with snap_room. Both ports under the shared f_axis_port set, and:
//   - fixed frame length: TLAST exactly on every FRAME_WORDS-th output word;
//   - frame_count == record frames out on m_axis, or one more while the closing words are
//     still in the output FIFO; no record frame before its 16 cells
//     (frames out <= cells in / 16).
`default_nettype none

module detect_records_props (
  input wire logic         clk,
  input wire logic         rst,
  input wire logic         snap_wr,
  input wire logic [127:0] snap_data,
  input wire logic [63:0]  s_axis_tdata,
  input wire logic         s_axis_tvalid,
  input wire logic         m_axis_tready
);
  localparam int FW = 9;   // FRAME_WORDS = MAX_DETECTIONS * (HDR 4 + TX 1) + HDR 4
  logic         snap_room, s_axis_tready, m_axis_tvalid, m_axis_tlast, trunc;
  logic [127:0] m_axis_tdata;
  logic [31:0]  frame_count;
  logic [3:0]   s_axis_tuser;

  detect_records #(.NUM_TX(1), .NUM_RX(4), .N_RANGE(4), .N_DOPPLER(4), .POW_W(8),
                   .SUM_W(12), .CNT_W(4), .SNAP_ROWS(4), .MAX_DETECTIONS(1)) dut (
    .clk, .rst, .cfg_max_detections(16'd1), .snap_wr, .snap_data, .snap_room, .s_axis_tdata, .s_axis_tvalid,
    .s_axis_tready, .s_axis_tuser, .m_axis_tdata, .m_axis_tvalid, .m_axis_tready,
    .m_axis_tlast, .status_truncated(trunc), .frame_count);

  initial assume (rst);

  logic [7:0] n_in, n_out;
  f_axis_port #(.PAYLOAD_W(68), .ASSUME(1'b1)) u_s (
    .clk, .rst, .tvalid(s_axis_tvalid), .tready(s_axis_tready),
    .payload({s_axis_tuser, s_axis_tdata}), .beats(n_in));
  f_axis_port #(.PAYLOAD_W(129)) u_m (
    .clk, .rst, .tvalid(m_axis_tvalid), .tready(m_axis_tready),
    .payload({m_axis_tlast, m_axis_tdata}), .beats(n_out));

  // the CFAR's cell order
  assign s_axis_tuser = {n_in[3:2], 2'(n_in[1:0] + 2'd1)};
  always_comb if (!rst && snap_wr) assume (snap_room);

  logic       past = 1'b0;
  logic [3:0] pos_q;       // word within the record frame
  logic [7:0] n_frames;
  always_ff @(posedge clk) begin
    past <= 1'b1;
    if (rst) begin
      pos_q    <= '0;
      n_frames <= '0;
    end else if (m_axis_tvalid && m_axis_tready) begin
      pos_q <= (pos_q == 4'(FW - 1)) ? '0 : pos_q + 4'd1;
      if (m_axis_tlast) n_frames <= n_frames + 8'd1;
    end
  end
  always_comb if (past && !rst) begin
    if (m_axis_tvalid) assert (m_axis_tlast == (pos_q == 4'(FW - 1)));
    // frame_count: frames whose last word was issued into the 4-word output FIFO, so at
    // most one closed frame has not yet left m_axis
    assert (n_frames <= frame_count[7:0] && frame_count[7:0] <= n_frames + 8'd1);
    if (frame_count[7:0] != n_frames) assert (m_axis_tvalid);
    assert ({n_frames, 4'd0} <= 12'(n_in) + (m_axis_tvalid ? 12'd0 : 12'd0));
  end
  always_comb if (past && !rst) begin
    cover (m_axis_tvalid && m_axis_tready && m_axis_tlast);
    cover (trunc);
  end
endmodule

`default_nettype wire
