// SPDX-License-Identifier: Apache-2.0
// Formal harnesses of the FFT pipeline stages (formal/fft_window.sby, fft_sdf_bf.sby,
// fft_twiddle.sby). The stages are not AXI-Stream: fft_axis moves every stage on one enable
// (en = adv), each stage carries (data, vld, pos[, ov]). The contract of each stage is the
// shared f_vld_pipe set (formal/f_props.sv): out_vld is in_vld exactly LAT enabled cycles
// later, out_pos is in_pos LAT enabled cycles later, samples in - out == samples in flight.
// Every input is free; en is free in the cover tasks and low at most FAIR cycles in a row in
// the prove tasks (k-induction needs the stages to move: every register of a stage loads
// only on en or rst, so a longer stall only repeats the state).
// Data properties where they are short: the window without taper is a shift by GUARD_W one
// enabled cycle later; the first SDF stage (D = 1, no rotation, no scaling) emits x0 + x1
// and x0 - x1 of each pair.
`default_nettype none

module fft_window_props #(
  parameter bit WINDOW = 1'b0,
  parameter int FAIR = 0
) (
  input wire logic       clk,
  input wire logic       rst,
  input wire logic       en,
  input wire logic [7:0] in_data,
  input wire logic       in_vld,
  input wire logic [2:0] in_pos
);
  localparam int DATA_W = 4, GUARD_W = 1, W = 5, LOG2N = 3;
  localparam int LAT = WINDOW ? 4 : 1;
  logic [2*W-1:0]   out_data;
  logic             out_vld;
  logic [LOG2N-1:0] out_pos;

  fft_window #(.NUM_CH(1), .DATA_W(DATA_W), .GUARD_W(GUARD_W), .W(W), .LOG2N(LOG2N),
               .WINDOW(WINDOW)) dut (
    .clk, .rst, .en, .in_data, .in_vld, .in_pos, .out_data, .out_vld, .out_pos);

  initial assume (rst);
  f_vld_pipe #(.LAT(LAT), .POS_W(LOG2N), .FAIR(FAIR)) u_pipe (
    .clk, .rst, .en, .in_vld, .in_pos, .out_vld, .out_pos);

  // data: without the taper, each component is sign-extended and shifted by GUARD_W
  logic       past = 1'b0;
  logic [7:0] d_q;
  always_ff @(posedge clk) begin
    past <= 1'b1;
    if (en) d_q <= in_data;
  end
  if (!WINDOW) begin : g_data
    always_comb if (past && !rst && out_vld) begin
      assert (out_data[W-1:0] == W'(signed'(d_q[3:0])) <<< GUARD_W);
      assert (out_data[2*W-1:W] == W'(signed'(d_q[7:4])) <<< GUARD_W);
    end
  end
endmodule

module fft_sdf_bf_props #(
  parameter int D = 1,
  parameter bit ROTATE = 1'b0,
  parameter int FAIR = 0
) (
  input wire logic       clk,
  input wire logic       rst,
  input wire logic       en,
  input wire logic [7:0] in_data,
  input wire logic       in_vld,
  input wire logic [2:0] in_pos,
  input wire logic       in_ov
);
  localparam int W = 4, LOG2N = 3;
  logic [2*W-1:0]   out_data;
  logic             out_vld, out_ov;
  logic [LOG2N-1:0] out_pos;

  fft_sdf_bf #(.NUM_CH(1), .W(W), .LOG2N(LOG2N), .D(D), .ROTATE(ROTATE), .INVERSE(1'b0),
               .SCALE(1'b0)) dut (
    .clk, .rst, .en, .in_data, .in_vld, .in_pos, .in_ov, .out_data, .out_vld, .out_pos,
    .out_ov);

  initial assume (rst);
  // samples arrive with consecutive positions (the pipeline order fft_axis feeds)
  logic [LOG2N-1:0] f_pos;
  always_ff @(posedge clk) begin
    if (rst) f_pos <= '0;
    else if (en) f_pos <= f_pos + 1'b1;
  end
  always_comb if (!rst) assume (in_pos == f_pos);

  f_vld_pipe #(.LAT(D + 2), .POS_W(LOG2N), .FAIR(FAIR)) u_pipe (
    .clk, .rst, .en, .in_vld, .in_pos, .out_vld, .out_pos);

  // data (D = 1, no rotation): the pair (x0 at even pos, x1 at odd pos) leaves as x0 + x1
  // (two enabled cycles after x1) then x0 - x1, saturated to W bits with the overflow flag
  if (D == 1 && !ROTATE) begin : g_data
    logic       past = 1'b0;
    logic [7:0] e_q, x0_q, x1_q;   // last even sample; the last complete pair
    logic [7:0] y0_q, y1_q;        // the pair before it
    logic       ove_q, ov0_q, ov1_q, ovy0_q, ovy1_q;
    logic [2:0] ph_q;        // enabled cycles since the pair's x1 (saturating)
    function automatic logic [W-1:0] f_sat(input logic signed [5:0] v);
      f_sat = (v > 6'sd7) ? W'(7) : (v < -6'sd8) ? W'(-8) : W'(v);
    endfunction
    function automatic logic f_ovf(input logic signed [5:0] v);
      f_ovf = (v > 6'sd7) || (v < -6'sd8);
    endfunction
    logic signed [5:0] sr, si, dr, di;
    assign sr = 6'(signed'(x0_q[3:0])) + 6'(signed'(x1_q[3:0]));
    assign si = 6'(signed'(x0_q[7:4])) + 6'(signed'(x1_q[7:4]));
    assign dr = 6'(signed'(y0_q[3:0])) - 6'(signed'(y1_q[3:0]));
    assign di = 6'(signed'(y0_q[7:4])) - 6'(signed'(y1_q[7:4]));
    always_ff @(posedge clk) begin
      past <= 1'b1;
      if (rst) ph_q <= 3'd7;
      else if (en) begin
        if (!in_pos[0]) begin
          e_q   <= in_data;
          ove_q <= in_ov;
        end else begin
          y0_q   <= x0_q;
          y1_q   <= x1_q;
          ovy0_q <= ov0_q;
          ovy1_q <= ov1_q;
          x0_q  <= e_q;
          ov0_q <= ove_q;
          x1_q  <= in_data;
          ov1_q <= in_ov;
        end
        ph_q <= in_pos[0] ? 3'd0 : (ph_q == 3'd7 ? 3'd7 : ph_q + 3'd1);
      end
    end
    // ph_q == 1: the last pair's sum leaves now; ph_q == 0 (after a later pair's x1, the
    // samples at consecutive positions): the pair before's difference leaves now
    always_comb if (past && !rst && out_vld) begin
      if (ph_q == 3'd1) begin
        assert (out_data == {f_sat(si), f_sat(sr)});
        assert (out_ov == (ov0_q | ov1_q | f_ovf(sr) | f_ovf(si)));
      end
      if (ph_q == 3'd0) begin
        assert (out_data == {f_sat(di), f_sat(dr)});
        assert (out_ov == (ovy0_q | ovy1_q | f_ovf(dr) | f_ovf(di)));
      end
    end
    always_comb if (past && !rst) begin
      cover (out_vld && ph_q == 3'd0 && out_ov && !ovy0_q && !ovy1_q);
    end
  end
endmodule

module fft_twiddle_props #(
  parameter int FAIR = 0,
  // W = 8 with MUL_W = 8: the products split (x = hi * 2^7 + lo, fft_twiddle MUL_W)
  parameter int W = 5,
  parameter int MUL_W = 27
) (
  input wire logic          clk,
  input wire logic          rst,
  input wire logic          en,
  input wire logic [2*W-1:0] in_data,
  input wire logic          in_vld,
  input wire logic [3:0]    in_pos,
  input wire logic          in_ov,
  input wire logic [3:0]    in_pos_ahead
);
  localparam int LOG2N = 4;
  logic [2*W-1:0]   out_data;
  logic             out_vld, out_ov;
  logic [LOG2N-1:0] out_pos;

  // in_pos_ahead is free; in_pos is its value two enabled cycles earlier (what the
  // butterfly before the twiddle gives: its head's index leaves two advances later), and no
  // valid sample enters before two enabled cycles have passed (the butterfly's two output
  // registers are reset)
  logic [LOG2N-1:0] pa1_q, pa2_q;
  logic [1:0]       n_en_q = 2'd0;
  always_ff @(posedge clk) begin
    if (en) begin
      pa1_q <= in_pos_ahead;
      pa2_q <= pa1_q;
      if (n_en_q != 2'd2) n_en_q <= n_en_q + 2'd1;
    end
  end
  always_comb assume (in_pos == pa2_q);
  always_comb assume (!in_vld || n_en_q == 2'd2);

  fft_twiddle #(.NUM_CH(1), .W(W), .LOG2N(LOG2N), .LOG2M(LOG2N), .INVERSE(1'b0),
                .MUL_W(MUL_W)) dut (
    .clk, .rst, .en, .in_data, .in_vld, .in_pos, .in_ov, .in_pos_ahead, .out_data, .out_vld,
    .out_pos, .out_ov);

  initial assume (rst);
  localparam int LAT = 5;   // fft_twiddle's stages
  f_vld_pipe #(.LAT(LAT), .POS_W(LOG2N), .FAIR(FAIR)) u_pipe (
    .clk, .rst, .en, .in_vld, .in_pos, .out_vld, .out_pos);

  // the overflow flag travels with its sample: an input flag always comes out set;
  // a position whose twiddle exponent i0 * (b1 + 2 b0) is 0 (i0 = pos[1:0] or the pair
  // {pos[2], pos[3]} zero) has twiddle 1 (cos 1, sin 0): the sample leaves unchanged, without
  // overflow (its coefficient looked up from its own position, two advances ahead)
  logic       past = 1'b0;
  logic [LAT-1:0] ov_q, p0_q;
  logic [LAT-1:0][2*W-1:0] d_q;
  always_ff @(posedge clk) begin
    past <= 1'b1;
    if (en) begin
      ov_q <= {ov_q[LAT-2:0], in_ov};
      p0_q <= {p0_q[LAT-2:0], in_pos[1:0] == 2'd0 || in_pos[3:2] == 2'd0};
      d_q  <= {d_q[LAT-2:0], in_data};
    end
  end
  always_comb if (past && !rst && out_vld) begin
    if (ov_q[LAT-1]) assert (out_ov);
    if (p0_q[LAT-1]) assert (out_data == d_q[LAT-1] && out_ov == ov_q[LAT-1]);
  end
  always_comb if (past && !rst) cover (out_vld && out_ov && !ov_q[LAT-1]);
endmodule

`default_nettype wire
