// SPDX-License-Identifier: Apache-2.0
// Formal harness of cfar_2d (formal/cfar_2d.sby): 4 range x 4 Doppler cells, POW_W 8,
// guard 0, training 1 cell each way (PR = PD = 1), default kind CA, the run-time kind and
// local-maximum setting and the 4-bit scales any constants the solver picks. Both ports
// under the shared f_axis_port set, and:
//   - every cell leaves exactly once, in order: output beat k carries tuser = {r, d} with
//     r = (k / 4) mod 4 and d = (k + PD) mod 4 (each row starts at d = PD, wraps to 0..PD-1),
//     TLAST on the last cell of every row; no cell before its input (out <= in);
//   - frame_count counts completed frames (<= input frames);
//   - status_framing_error is exactly "some input TLAST not on Doppler bin 3" (positions
//     counted here from the input beats: a beat taken without being used shows here);
//   - in the first frame after reset, every output cell carries its own input power and
//     the powers of its four neighbours (r-1, r+1: 0 beyond rows 0 and 3; d-1, d+1:
//     circular): checked on one watched cell, any cell (the solver's pick).
`default_nettype none

module cfar_2d_props (
  input wire logic       clk,
  input wire logic       rst,
  input wire logic [7:0] s_axis_tdata,
  input wire logic       s_axis_tvalid,
  input wire logic       s_axis_tlast,
  input wire logic       m_axis_tready
);
  localparam int NR = 4, ND = 4, PD = 1;
  localparam int POW_W = 8, CNT_W = 4, SUM_W = 12, OUT_W = 64;
  (* anyconst *) logic [3*4-1:0] cfg_scale;
  (* anyconst *) logic [1:0] cfg_kind;       // any kind (OS not built: KIND)
  (* anyconst *) logic       cfg_local_max;

  logic             s_axis_tready, m_axis_tvalid, m_axis_tlast, framing;
  logic [OUT_W-1:0] m_axis_tdata;
  logic [3:0]       m_axis_tuser;
  logic [31:0]      frame_count, detection_count;

  cfar_2d #(.N_RANGE(NR), .N_DOPPLER(ND), .POW_W(POW_W), .GUARD_R(0), .GUARD_D(0),
            .TRAIN_R(1), .TRAIN_D(1), .KIND(0), .SCALE_W(4), .SCALE_FRAC(1)) dut (
    .clk, .rst, .cfg_scale, .cfg_kind, .cfg_local_max,
    .s_axis_tdata, .s_axis_tvalid, .s_axis_tready, .s_axis_tlast,
    .m_axis_tdata, .m_axis_tvalid, .m_axis_tready, .m_axis_tlast, .m_axis_tuser,
    .status_framing_error(framing), .frame_count, .detection_count);

  initial assume (rst);

  logic [7:0] n_in, n_out;
  f_axis_port #(.PAYLOAD_W(9), .ASSUME(1'b1)) u_s (
    .clk, .rst, .tvalid(s_axis_tvalid), .tready(s_axis_tready),
    .payload({s_axis_tlast, s_axis_tdata}), .beats(n_in));
  f_axis_port #(.PAYLOAD_W(OUT_W + 5)) u_m (
    .clk, .rst, .tvalid(m_axis_tvalid), .tready(m_axis_tready),
    .payload({m_axis_tuser, m_axis_tlast, m_axis_tdata}), .beats(n_out));

  logic       past = 1'b0;
  logic [7:0] n_det;
  logic       f_err;
  wire        det_flag = m_axis_tdata[POW_W + SUM_W + CNT_W];
  always_ff @(posedge clk) begin
    past <= 1'b1;
    if (rst) begin
      n_det <= '0;
      f_err <= 1'b0;
    end else begin
      if (m_axis_tvalid && m_axis_tready && det_flag) n_det <= n_det + 8'd1;
      if (s_axis_tvalid && s_axis_tready && s_axis_tlast != (n_in[1:0] == 2'd3)) f_err <= 1'b1;
    end
  end

  wire [1:0] exp_r = n_out[3:2];
  wire [1:0] exp_d = 2'(n_out[1:0] + 2'(PD));

  // one watched cell of the first frame after reset (the solver's pick): its input power,
  // then every output cell whose own or neighbour field is that cell must carry it
  localparam int NB = POW_W + SUM_W + CNT_W + 1;    // first neighbour field
  (* anyconst *) logic [3:0] f_idx;                 // watched cell {r, d}
  logic [POW_W-1:0] f_val;
  logic             f_have;
  always_ff @(posedge clk) begin
    if (rst) f_have <= 1'b0;
    else if (s_axis_tvalid && s_axis_tready && n_in < 8'd16 && n_in[3:0] == f_idx) begin
      f_val  <= s_axis_tdata;
      f_have <= 1'b1;
    end
  end
  wire [1:0] f_r = f_idx[3:2], f_d = f_idx[1:0];
  always_comb if (past && !rst && m_axis_tvalid && n_out < 8'd16) begin
    if (f_r == exp_r && f_d == exp_d)
      assert (f_have && m_axis_tdata[POW_W-1:0] == f_val);
    if (exp_r == 2'd0) assert (m_axis_tdata[NB +: POW_W] == '0);
    else if (f_r == exp_r - 2'd1 && f_d == exp_d)
      assert (f_have && m_axis_tdata[NB +: POW_W] == f_val);
    if (exp_r == 2'd3) assert (m_axis_tdata[NB + POW_W +: POW_W] == '0);
    else if (f_r == exp_r + 2'd1 && f_d == exp_d)
      assert (f_have && m_axis_tdata[NB + POW_W +: POW_W] == f_val);
    if (f_r == exp_r && f_d == 2'(exp_d - 2'd1))
      assert (f_have && m_axis_tdata[NB + 2 * POW_W +: POW_W] == f_val);
    if (f_r == exp_r && f_d == 2'(exp_d + 2'd1))
      assert (f_have && m_axis_tdata[NB + 3 * POW_W +: POW_W] == f_val);
  end

  always_comb if (past && !rst) begin
    assert (n_out <= n_in);
    if (m_axis_tvalid) begin
      assert (n_out != n_in);
      assert (m_axis_tuser == {exp_r, exp_d});
      assert (m_axis_tlast == (n_out[1:0] == 2'd3));
    end
    assert (frame_count[7:0] <= {4'd0, n_in[7:4]});
    assert (framing == f_err);
  end
  always_comb if (past && !rst) begin
    cover (m_axis_tvalid && m_axis_tready && det_flag);
    cover (m_axis_tvalid && m_axis_tready && m_axis_tlast && exp_r == 2'd1);
    cover (framing);
  end
  wire unused = ^{framing, detection_count, n_det};
endmodule

`default_nettype wire
