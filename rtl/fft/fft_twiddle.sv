// SPDX-License-Identifier: Apache-2.0
// Twiddle multiplier between two radix-2^2 stage pairs of the streaming FFT: looks up
// W_M^(i0*(b1+2*b0)) in the quarter-wave ROM from the sample's index tag and multiplies every
// lane with registered inputs and products (DSP48E2 friendly; three real products per lane,
// Gauss, four for W = 27), exact sums, convergent rounding, saturation.
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
  localparam int COEF_W = fft_rom_pkg::COEF_W;
  localparam int COEF_FRAC = fft_rom_pkg::COEF_FRAC;

  localparam int DW = NUM_CH * 2 * W;
  localparam int PRW = W + COEF_W;   // product width
  // Three real multipliers per lane (Gauss) when the pre-added operand re + im (W+1 bits)
  // fits a DSP48E2 A port (27 bits), else four. Same exact products, so the same bits.
  localparam bit GAUSS = (W + 1 <= 27);

  if (LOG2M < 3 || LOG2M > LOG2N || LOG2N > ROM_LOG2) begin : g_bad_log2m
    $fatal(1, "%m: LOG2M=%0d must be in 3..LOG2N and LOG2N <= %0d", LOG2M, ROM_LOG2);
  end

  // ---------------------------------------------------------------- ROM index from the tag
  logic [ROM_LOG2-1:0] rom_idx;
  always_comb begin
    logic [ROM_LOG2-1:0] i0, e;
    logic [1:0] m;
    i0 = ROM_LOG2'(in_pos[LOG2M-3:0]);
    m  = {in_pos[LOG2M-2], in_pos[LOG2M-1]};   // b1 + 2*b0
    e  = ROM_LOG2'(i0 * ROM_LOG2'(m));
    rom_idx = e << (ROM_LOG2 - LOG2M);
  end

  // C = COS(k), S = SIN(k) = COS(k - 1024): quarter-wave ROM (generated, combinational)
  logic [COEF_W-1:0] rom_cos, rom_sin;
  fft_twiddle_rom u_rom (.k(rom_idx), .cos_o(rom_cos), .sin_o(rom_sin));

  // ---------------------------------------------------------------- stage 1: operands
  logic [DW-1:0]        d1_q;
  logic [LOG2N-1:0]     pos1_q, pos2_q, pos3_q;
  logic                 ov1_q, ov2_q, ov3_q;
  logic                 vld1_q, vld2_q, vld3_q;

  // ---------------------------------------------------------------- stage 3: sum, round
  logic [DW-1:0] y_d, y3_q;
  logic          y_ov;

  // Products (stage 2) and the exact sums yr = re*C + im*S, yi = im*C - re*S (forward;
  // the inverse has S -> -S), full precision before the rounding: two forms, same bits.
  logic signed [63:0] yr_full [NUM_CH];
  logic signed [63:0] yi_full [NUM_CH];

  if (GAUSS) begin : g_gauss
    // Three real products per lane (Gauss): with d = -S (forward) or +S (inverse)
    //   k1 = C*(re + im), k2 = re*(d - C), k3 = im*(C + d), yr = k1 - k3, yi = k1 + k2.
    // |C +- S| <= 92682 < 2^17, so both coefficient sums stay COEF_W bits (one per twiddle,
    // shared by every lane); the data pre-add re + im is W+1 <= 27 bits (DSP48E2 A port).
    logic signed [COEF_W-1:0] c1_q, p1_q, m1_q;   // C, d - C, C + d
    logic signed [W:0]        a1_q [NUM_CH];      // re + im
    logic signed [PRW:0]      k1_q [NUM_CH];
    logic signed [PRW-1:0]    k2_q [NUM_CH];
    logic signed [PRW-1:0]    k3_q [NUM_CH];
    logic signed [COEF_W:0]   cc, ss;

    assign cc = (COEF_W+1)'(signed'(rom_cos));
    assign ss = (COEF_W+1)'(signed'(rom_sin));

    always_ff @(posedge clk) begin
      if (en) begin
        c1_q <= signed'(rom_cos);
        p1_q <= COEF_W'(INVERSE ? ss - cc : -ss - cc);
        m1_q <= COEF_W'(INVERSE ? cc + ss : cc - ss);
        for (int ch = 0; ch < NUM_CH; ch++) begin
          a1_q[ch] <= (W+1)'(signed'(in_data[ch*2*W +: W]))
                    + (W+1)'(signed'(in_data[ch*2*W + W +: W]));
          k1_q[ch] <= (PRW+1)'(a1_q[ch]) * (PRW+1)'(c1_q);
          k2_q[ch] <= PRW'(signed'(d1_q[ch*2*W +: W])) * PRW'(p1_q);
          k3_q[ch] <= PRW'(signed'(d1_q[ch*2*W + W +: W])) * PRW'(m1_q);
        end
      end
    end

    always_comb begin
      for (int ch = 0; ch < NUM_CH; ch++) begin
        yr_full[ch] = 64'(k1_q[ch]) - 64'(k3_q[ch]);
        yi_full[ch] = 64'(k1_q[ch]) + 64'(k2_q[ch]);
      end
    end
  end else begin : g_four
    // Four real products per lane (W = 27: the pre-add would not fit the 27-bit A port).
    logic signed [COEF_W-1:0] c1_q, s1_q;
    logic signed [PRW-1:0] prc_r_q [NUM_CH];   // re*C
    logic signed [PRW-1:0] prs_i_q [NUM_CH];   // im*S
    logic signed [PRW-1:0] prc_i_q [NUM_CH];   // im*C
    logic signed [PRW-1:0] prs_r_q [NUM_CH];   // re*S

    always_ff @(posedge clk) begin
      if (en) begin
        c1_q <= signed'(rom_cos);
        s1_q <= signed'(rom_sin);
        for (int ch = 0; ch < NUM_CH; ch++) begin
          prc_r_q[ch] <= PRW'(signed'(d1_q[ch*2*W +: W])) * PRW'(c1_q);
          prs_i_q[ch] <= PRW'(signed'(d1_q[ch*2*W + W +: W])) * PRW'(s1_q);
          prc_i_q[ch] <= PRW'(signed'(d1_q[ch*2*W + W +: W])) * PRW'(c1_q);
          prs_r_q[ch] <= PRW'(signed'(d1_q[ch*2*W +: W])) * PRW'(s1_q);
        end
      end
    end

    always_comb begin
      for (int ch = 0; ch < NUM_CH; ch++) begin
        if (INVERSE) begin   // x * (C + jS)
          yr_full[ch] = 64'(prc_r_q[ch]) - 64'(prs_i_q[ch]);
          yi_full[ch] = 64'(prc_i_q[ch]) + 64'(prs_r_q[ch]);
        end else begin       // x * (C - jS)
          yr_full[ch] = 64'(prc_r_q[ch]) + 64'(prs_i_q[ch]);
          yi_full[ch] = 64'(prc_i_q[ch]) - 64'(prs_r_q[ch]);
        end
      end
    end
  end

  always_ff @(posedge clk) begin
    if (en) begin
      d1_q   <= in_data;
      pos1_q <= in_pos;
      ov1_q  <= in_ov;
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
      yr = fft_pkg::round_conv(yr_full[ch], COEF_FRAC);
      yi = fft_pkg::round_conv(yi_full[ch], COEF_FRAC);
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
