// SPDX-License-Identifier: Apache-2.0
// Twiddle multiplier between two radix-2^2 stage pairs of the streaming FFT: looks up
// W_M^(i0*(b1+2*b0)) in the shared ROM from the sample's index tag and multiplies every lane
// with registered inputs and products (DSP48E2 friendly), convergent rounding, saturation.
`default_nettype none

module fft_twiddle #(
  // Lanes processed in parallel, 1..16.
  parameter int NUM_CH = 1,
  // Bits of I and of Q inside the pipeline, 8..27 (the DSP48E2 A port).
  parameter int W = 21,
  // log2 of the transform length, 4..12.
  parameter int LOG2N = 6,
  // log2 of the sub-transform length M this twiddle belongs to, 3..LOG2N.
  parameter int LOG2M = 6,
  // 1: inverse transform (conjugate twiddles).
  parameter bit INVERSE = 0
) (
  input  logic clk,
  input  logic rst,
  // Pipeline advance.
  input  logic en,
  // Sample in.
  input  logic [NUM_CH*2*W-1:0] in_data,
  input  logic                  in_vld,
  input  logic [LOG2N-1:0]      in_pos,
  input  logic                  in_ov,
  // Sample out, 3 advances later.
  output logic [NUM_CH*2*W-1:0] out_data,
  output logic                  out_vld,
  output logic [LOG2N-1:0]      out_pos,
  output logic                  out_ov
);
  // coefficient ROM geometry (rtl/fft/fft_rom_pkg.sv, generated)
  localparam int ROM_LOG2 = fft_rom_pkg::ROM_LOG2;
  localparam int ROM_SIZE = fft_rom_pkg::ROM_SIZE;
  localparam int COEF_W = fft_rom_pkg::COEF_W;
  localparam int COEF_FRAC = fft_rom_pkg::COEF_FRAC;

  localparam int DW = NUM_CH * 2 * W;
  localparam int PRW = W + COEF_W;   // product width

  if (LOG2M < 3 || LOG2M > LOG2N || LOG2N > ROM_LOG2) begin : g_bad_log2m
    $fatal(1, "%m: LOG2M=%0d must be in 3..LOG2N and LOG2N <= %0d", LOG2M, ROM_LOG2);
  end

  // ---------------------------------------------------------------- ROM index from the tag
  logic [ROM_LOG2-1:0] rom_idx, sin_idx;
  always_comb begin
    logic [ROM_LOG2-1:0] i0, e;
    logic [1:0] m;
    i0 = ROM_LOG2'(in_pos[LOG2M-3:0]);
    m  = {in_pos[LOG2M-2], in_pos[LOG2M-1]};   // b1 + 2*b0
    e  = ROM_LOG2'(i0 * ROM_LOG2'(m));
    rom_idx = e << (ROM_LOG2 - LOG2M);
    sin_idx = rom_idx - ROM_LOG2'(ROM_SIZE / 4);
  end

  // ---------------------------------------------------------------- stage 1: operands
  logic [DW-1:0]        d1_q;
  logic [LOG2N-1:0]     pos1_q, pos2_q, pos3_q;
  logic                 ov1_q, ov2_q, ov3_q;
  logic                 vld1_q, vld2_q, vld3_q;
  logic signed [COEF_W-1:0] c1_q, s1_q;

  // ---------------------------------------------------------------- stage 2: products
  logic signed [PRW-1:0] prc_r_q [NUM_CH];   // re*C
  logic signed [PRW-1:0] prs_i_q [NUM_CH];   // im*S
  logic signed [PRW-1:0] prc_i_q [NUM_CH];   // im*C
  logic signed [PRW-1:0] prs_r_q [NUM_CH];   // re*S

  // ---------------------------------------------------------------- stage 3: sum, round
  logic [DW-1:0] y_d, y3_q;
  logic          y_ov;

  always_ff @(posedge clk) begin
    if (en) begin
      d1_q   <= in_data;
      pos1_q <= in_pos;
      ov1_q  <= in_ov;
      c1_q   <= signed'(fft_rom_pkg::COS(rom_idx));
      s1_q   <= signed'(fft_rom_pkg::COS(sin_idx));
      for (int ch = 0; ch < NUM_CH; ch++) begin
        prc_r_q[ch] <= PRW'(signed'(d1_q[ch*2*W +: W])) * PRW'(c1_q);
        prs_i_q[ch] <= PRW'(signed'(d1_q[ch*2*W + W +: W])) * PRW'(s1_q);
        prc_i_q[ch] <= PRW'(signed'(d1_q[ch*2*W + W +: W])) * PRW'(c1_q);
        prs_r_q[ch] <= PRW'(signed'(d1_q[ch*2*W +: W])) * PRW'(s1_q);
      end
      pos2_q <= pos1_q;
      ov2_q  <= ov1_q;
      y3_q   <= y_d;
      pos3_q <= pos2_q;
      ov3_q  <= ov2_q | y_ov;
    end
  end

  always_comb begin
    logic signed [63:0] yr, yi;
    y_d  = '0;
    y_ov = 1'b0;
    for (int ch = 0; ch < NUM_CH; ch++) begin
      if (INVERSE) begin   // x * (C + jS)
        yr = 64'(prc_r_q[ch]) - 64'(prs_i_q[ch]);
        yi = 64'(prc_i_q[ch]) + 64'(prs_r_q[ch]);
      end else begin       // x * (C - jS)
        yr = 64'(prc_r_q[ch]) + 64'(prs_i_q[ch]);
        yi = 64'(prc_i_q[ch]) - 64'(prs_r_q[ch]);
      end
      yr = fft_pkg::round_conv(yr, COEF_FRAC);
      yi = fft_pkg::round_conv(yi, COEF_FRAC);
      y_ov = y_ov | fft_pkg::sat_ov(yr, W) | fft_pkg::sat_ov(yi, W);
      y_d[ch*2*W +: W]     = W'(fft_pkg::sat_val(yr, W));
      y_d[ch*2*W + W +: W] = W'(fft_pkg::sat_val(yi, W));
    end
  end

  always_ff @(posedge clk) begin
    if (rst) begin
      vld1_q <= 1'b0;
      vld2_q <= 1'b0;
      vld3_q <= 1'b0;
    end else if (en) begin
      vld1_q <= in_vld;
      vld2_q <= vld1_q;
      vld3_q <= vld2_q;
    end
  end

  assign out_data = y3_q;
  assign out_vld  = vld3_q;
  assign out_pos  = pos3_q;
  assign out_ov   = ov3_q;
endmodule

`default_nettype wire
