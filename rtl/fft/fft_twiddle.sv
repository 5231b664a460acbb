// SPDX-License-Identifier: Apache-2.0
// Twiddle multiplier between two radix-2^2 stage pairs of the streaming FFT: looks up
// W_M^(i0*(b1+2*b0)) in the quarter-wave ROM from the sample's index tag and multiplies every
// lane with registered inputs and products (DSP48E2 friendly; three real products per lane,
// Gauss, four for W = 27), exact sums, convergent rounding, saturation.
// Seven register stages: ROM index; quarter-wave ROM words; coefficients (quadrant, Gauss
// pre-adds) and data pre-add; every multiplier's own operands; products; exact sums; rounded
// and saturated result.
// The operand stage gives each lane's products their own copy of the shared coefficients and
// of the data (one fan-out each), so a place and route puts them beside the multiplier
// (on an ECP5 a product wider than 18 bits is two MULT18X18D and the sum of their partial
// products in fabric, all in the product's cycle, with the routes to and from the
// multipliers; on a DSP48E2 the two operand stages are the A1/A2 and B1/B2 registers, one
// slice per product).
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
  // Sample out, 7 advances later.
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

  // ---------------------------------------------------------------- stage 1: ROM index
  // e = i0 * m, m = {in_pos[LOG2M-2], in_pos[LOG2M-1]} (b1 + 2*b0), as a shift-add (no
  // multiplier); ROM index e * 2^(ROM_LOG2 - LOG2M)
  logic [ROM_LOG2-1:0] idx_q;
  always_ff @(posedge clk) begin
    logic [ROM_LOG2-1:0] i0;
    if (en) begin
      i0 = ROM_LOG2'(in_pos[LOG2M-3:0]);
      idx_q <= ROM_LOG2'(((in_pos[LOG2M-1] ? i0 : '0) + (in_pos[LOG2M-2] ? i0 << 1 : '0))
                         << (ROM_LOG2 - LOG2M));
    end
  end

  // ---------------------------------------------------------------- stage 2: ROM words
  // C = COS(k), S = SIN(k) = COS(k - 1024): quarter-wave ROM (generated, combinational),
  // registered
  logic [COEF_W-1:0] rom_cos, rom_sin, cos2_q, sin2_q;
  fft_twiddle_rom u_rom (.k(idx_q), .cos_o(rom_cos), .sin_o(rom_sin));
  always_ff @(posedge clk) begin
    if (en) begin
      cos2_q <= rom_cos;
      sin2_q <= rom_sin;
    end
  end

  // ---------------------------------------------------------------- stages 3, 4: operands
  logic [DW-1:0]        da_q, db_q, d1_q, d4_q;   // data in stages 1, 2, 3, 4
  logic [LOG2N-1:0]     pos_q [7];
  logic                 ov_q  [6];
  logic [6:0]           vld_q;

  // ---------------------------------------------------------------- stage 7: round, sat
  logic [DW-1:0] y_d, y7_q;
  logic          y_ov, ov7_q;

  // Products (stage 5) and the exact sums yr = re*C + im*S, yi = im*C - re*S (forward;
  // the inverse has S -> -S), full precision before the rounding (stage 6): two forms,
  // same bits.
  logic signed [PRW+1:0] yr_full [NUM_CH], yi_full [NUM_CH];
  logic signed [PRW+1:0] yr6_q [NUM_CH], yi6_q [NUM_CH];

  if (GAUSS) begin : g_gauss
    // Three real products per lane (Gauss): with d = -S (forward) or +S (inverse)
    //   k1 = C*(re + im), k2 = re*(d - C), k3 = im*(-C - d), yr = k1 + k3, yi = k1 + k2.
    // |C +- S| <= 92682 < 2^17, so both coefficient sums stay COEF_W bits (one per twiddle,
    // shared by every lane); the data pre-add re + im is W+1 <= 27 bits (DSP48E2 A port).
    // Both sums are additions of a product to k1 (k3 takes the negated coefficient), the form
    // a DSP48E2 post-adder with its P register takes (C port = k1).
    logic signed [COEF_W-1:0] c1_q, p1_q, m1_q;   // C, d - C, -C - d
    logic signed [W:0]        a1_q [NUM_CH];      // re + im
    // stage 4: each lane's operands (the coefficients copied per lane)
    logic signed [COEF_W-1:0] c4_q [NUM_CH], p4_q [NUM_CH], m4_q [NUM_CH];
    logic signed [W:0]        a4_q [NUM_CH];
    logic signed [PRW:0]      k1_q [NUM_CH];
    logic signed [PRW-1:0]    k2_q [NUM_CH];
    logic signed [PRW-1:0]    k3_q [NUM_CH];
    logic signed [COEF_W:0]   cc, ss;

    assign cc = (COEF_W+1)'(signed'(cos2_q));
    assign ss = (COEF_W+1)'(signed'(sin2_q));

    always_ff @(posedge clk) begin
      if (en) begin
        c1_q <= signed'(cos2_q);
        p1_q <= COEF_W'(INVERSE ? ss - cc : -ss - cc);
        m1_q <= COEF_W'(INVERSE ? -cc - ss : ss - cc);
        for (int ch = 0; ch < NUM_CH; ch++) begin
          a1_q[ch] <= (W+1)'(signed'(db_q[ch*2*W +: W]))
                    + (W+1)'(signed'(db_q[ch*2*W + W +: W]));
          a4_q[ch] <= a1_q[ch];
          k1_q[ch] <= (PRW+1)'(a4_q[ch]) * (PRW+1)'(c4_q[ch]);
          k2_q[ch] <= PRW'(signed'(d4_q[ch*2*W +: W])) * PRW'(p4_q[ch]);
          k3_q[ch] <= PRW'(signed'(d4_q[ch*2*W + W +: W])) * PRW'(m4_q[ch]);
        end
      end
    end

    // keep: the per-lane copies hold the same bits, which Yosys' opt_merge would merge back
    // into one register feeding every lane's multipliers
    (* keep *) always_ff @(posedge clk) begin
      if (en) begin
        for (int ch = 0; ch < NUM_CH; ch++) begin
          c4_q[ch] <= c1_q;
          p4_q[ch] <= p1_q;
          m4_q[ch] <= m1_q;
        end
      end
    end

    always_comb begin
      for (int ch = 0; ch < NUM_CH; ch++) begin
        yr_full[ch] = (PRW+2)'(k1_q[ch]) + (PRW+2)'(k3_q[ch]);
        yi_full[ch] = (PRW+2)'(k1_q[ch]) + (PRW+2)'(k2_q[ch]);
      end
    end
  end else begin : g_four
    // Four real products per lane (W = 27: the pre-add would not fit the 27-bit A port).
    logic signed [COEF_W-1:0] c1_q, s1_q;
    logic signed [COEF_W-1:0] c4_q [NUM_CH], s4_q [NUM_CH];   // stage 4: per lane
    logic signed [PRW-1:0] prc_r_q [NUM_CH];   // re*C
    logic signed [PRW-1:0] prs_i_q [NUM_CH];   // im*S
    logic signed [PRW-1:0] prc_i_q [NUM_CH];   // im*C
    logic signed [PRW-1:0] prs_r_q [NUM_CH];   // re*S

    always_ff @(posedge clk) begin
      if (en) begin
        c1_q <= signed'(cos2_q);
        s1_q <= signed'(sin2_q);
        for (int ch = 0; ch < NUM_CH; ch++) begin
          prc_r_q[ch] <= PRW'(signed'(d4_q[ch*2*W +: W])) * PRW'(c4_q[ch]);
          prs_i_q[ch] <= PRW'(signed'(d4_q[ch*2*W + W +: W])) * PRW'(s4_q[ch]);
          prc_i_q[ch] <= PRW'(signed'(d4_q[ch*2*W + W +: W])) * PRW'(c4_q[ch]);
          prs_r_q[ch] <= PRW'(signed'(d4_q[ch*2*W +: W])) * PRW'(s4_q[ch]);
        end
      end
    end

    // keep: per-lane copies of the same bits (see g_gauss)
    (* keep *) always_ff @(posedge clk) begin
      if (en) begin
        for (int ch = 0; ch < NUM_CH; ch++) begin
          c4_q[ch] <= c1_q;
          s4_q[ch] <= s1_q;
        end
      end
    end

    always_comb begin
      for (int ch = 0; ch < NUM_CH; ch++) begin
        if (INVERSE) begin   // x * (C + jS)
          yr_full[ch] = (PRW+2)'(prc_r_q[ch]) - (PRW+2)'(prs_i_q[ch]);
          yi_full[ch] = (PRW+2)'(prc_i_q[ch]) + (PRW+2)'(prs_r_q[ch]);
        end else begin       // x * (C - jS)
          yr_full[ch] = (PRW+2)'(prc_r_q[ch]) + (PRW+2)'(prs_i_q[ch]);
          yi_full[ch] = (PRW+2)'(prc_i_q[ch]) - (PRW+2)'(prs_r_q[ch]);
        end
      end
    end
  end

  always_ff @(posedge clk) begin
    if (en) begin
      da_q     <= in_data;
      db_q     <= da_q;
      d1_q     <= db_q;
      d4_q     <= d1_q;
      pos_q[0] <= in_pos;
      ov_q[0]  <= in_ov;
      for (int k = 1; k < 7; k++) pos_q[k] <= pos_q[k-1];
      for (int k = 1; k < 6; k++) ov_q[k] <= ov_q[k-1];
      for (int ch = 0; ch < NUM_CH; ch++) begin
        yr6_q[ch] <= yr_full[ch];
        yi6_q[ch] <= yi_full[ch];
      end
      y7_q     <= y_d;
      ov7_q    <= ov_q[5] | y_ov;
    end
  end

  always_comb begin
    logic signed [63:0] yr, yi;
    y_d  = '0;
    y_ov = 1'b0;
    for (int ch = 0; ch < NUM_CH; ch++) begin
      yr = fft_pkg::round_conv(64'(yr6_q[ch]), COEF_FRAC);
      yi = fft_pkg::round_conv(64'(yi6_q[ch]), COEF_FRAC);
      y_ov = y_ov | fft_pkg::sat_ov(yr, W) | fft_pkg::sat_ov(yi, W);
      y_d[ch*2*W +: W]     = W'(fft_pkg::sat_val(yr, W));
      y_d[ch*2*W + W +: W] = W'(fft_pkg::sat_val(yi, W));
    end
  end

  always_ff @(posedge clk) begin
    if (rst) begin
      vld_q <= '0;
    end else if (en) begin
      vld_q <= {vld_q[5:0], in_vld};
    end
  end

  assign out_data = y7_q;
  assign out_vld  = vld_q[6];
  assign out_pos  = pos_q[6];
  assign out_ov   = ov7_q;
endmodule

`default_nettype wire
