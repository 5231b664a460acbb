// SPDX-License-Identifier: Apache-2.0
// Twiddle multiplier between two radix-2^2 stage pairs of the streaming FFT: looks up
// W_M^(i0*(b1+2*b0)) in the quarter-wave ROM from the sample's index tag and multiplies every
// lane with registered inputs and products (DSP48E2 friendly; three real products per lane,
// Gauss, four for W = 27), exact sums, convergent rounding, saturation.
// The coefficient runs two advances ahead of its sample: the ROM index is formed from
// in_pos_ahead, the index of the sample that enters two advances later (the preceding
// butterfly's delay-line head), and the quarter-wave ROM words are registered by the time that
// sample enters, so the data needs no delay to wait for them. Five register stages from
// in_data: coefficients (quadrant, Gauss pre-adds) and data pre-add; every multiplier's own
// operands; products; exact sums; rounded and saturated result.
// The operand stage gives each lane's products their own copy of the shared coefficients and
// of the data (one fan-out each), so a place and route puts them beside the multiplier
// (on an ECP5 a product wider than 18 bits is two MULT18X18D and the sum of their partial
// products in fabric, all in the product's cycle, with the routes to and from the
// multipliers; on a DSP48E2 the two operand stages are the A1/A2 and B1/B2 registers, one
// slice per product).
// MUL_W < 27 (a MULT18X18D: 18): when the data operands (W+1 bits with Gauss, the pre-add;
// re and im sign-extended to it) are wider than MUL_W, each is split into an unsigned low
// part of MUL_W-1 bits and a signed high part, x = hi * 2^(MUL_W-1) + lo; both partial
// products are registered in the product stage and added, shifted, in the exact sums: the
// same stages and bits, and on an ECP5 no fabric sum of partial products before a register.
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
  parameter bit INVERSE = 0,
  // Widest signed data operand of one multiplier, 8..27: 27 a DSP48E2 A port (no split at
  // any W), 18 a MULT18X18D (wider operands are split in two products, see above).
  parameter int MUL_W = 27
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
  // Index of the sample that enters two advances later (in_pos then).
  input  logic [LOG2N-1:0]      in_pos_ahead,
  // Sample out, 5 advances later.
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
  localparam int Y_W = fft_pkg::round_w(PRW + 2, COEF_FRAC);   // the rounded product's bits
  // Three real multipliers per lane (Gauss) when the pre-added operand re + im (W+1 bits)
  // fits a DSP48E2 A port (27 bits), else four. Same exact products, so the same bits.
  localparam bit GAUSS = (W + 1 <= 27);
  // The data operand of every product: W+1 bits with Gauss (re + im; re, im sign-extended),
  // W without; split at bit MUL_W-1 when wider than MUL_W.
  localparam int XW = GAUSS ? W + 1 : W;
  localparam bit SPLIT = XW > MUL_W;
  localparam int LO_W = MUL_W - 1;                 // low part bits (unsigned)
  localparam int HI_W = SPLIT ? XW - LO_W : 1;     // high part bits (signed)
  localparam int LPW = MUL_W + COEF_W;             // low partial product width
  localparam int HPW = HI_W + COEF_W;              // high partial product width

  if (LOG2M < 3 || LOG2M > LOG2N || LOG2N > ROM_LOG2) begin : g_bad_log2m
    $fatal(1, "%m: LOG2M=%0d must be in 3..LOG2N and LOG2N <= %0d", LOG2M, ROM_LOG2);
  end
  if (MUL_W < 8 || MUL_W > 27) begin : g_bad_mul_w
    $fatal(1, "%m: MUL_W=%0d must be in 8..27", MUL_W);
  end

  // ------------------------------------------------ two advances ahead: ROM index
  // e = i0 * m, m = {pos[LOG2M-2], pos[LOG2M-1]} (b1 + 2*b0), as a shift-add (no
  // multiplier); ROM index e * 2^(ROM_LOG2 - LOG2M); pos = in_pos_ahead
  logic [ROM_LOG2-1:0] idx_q;
  always_ff @(posedge clk) begin
    logic [ROM_LOG2-1:0] i0;
    if (en) begin
      i0 = ROM_LOG2'(in_pos_ahead[LOG2M-3:0]);
      idx_q <= ROM_LOG2'(((in_pos_ahead[LOG2M-1] ? i0 : '0)
                          + (in_pos_ahead[LOG2M-2] ? i0 << 1 : '0)) << (ROM_LOG2 - LOG2M));
    end
  end

  // ------------------------------------------------ one advance ahead: ROM words
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

  // ---------------------------------------------------------------- stages 1, 2: operands
  logic [DW-1:0]        d1_q, d2_q;   // data in stages 1, 2
  // each lane's pre-add re + im in stages 1, 2: the data operand of the Gauss product k1
  // (unused by the four-product form, which synthesis then drops)
  /* verilator lint_off UNUSEDSIGNAL */
  logic signed [W:0]    a1_q [NUM_CH], a2_q [NUM_CH];
  /* verilator lint_on UNUSEDSIGNAL */
  logic [LOG2N-1:0]     pos_q [5];
  logic                 ov_q  [4];
  logic [4:0]           vld_q;

  // The coefficients of stage 1 (shared by the lanes) and their per-lane copies of stage 2:
  // NCF words (Gauss: C, d - C, -C - d; four products: C, S), lane ch's word i at
  // ch * NCF + i.
  localparam int NCF = GAUSS ? 3 : 2;
  logic signed [COEF_W-1:0] cf1_q [NCF];
  logic signed [COEF_W-1:0] cf2_q [NUM_CH * NCF];

  // The split form's table (g_split): data operand of product p of a lane (OP_PRE the
  // pre-add re + im, OP_RE, OP_IM) and its coefficient word within the lane's NCF.
  //   Gauss: k1 = pre-add * C, k2 = re * (d - C), k3 = im * (-C - d)
  //   four:  re * C, im * S, im * C, re * S
  localparam int OP_PRE = 0, OP_RE = 1, OP_IM = 2;
  function automatic int split_op(int p);
    if (GAUSS) split_op = p;
    else       split_op = (p == 1 || p == 2) ? OP_IM : OP_RE;
  endfunction
  function automatic int split_cf(int p);
    split_cf = GAUSS ? p : p % 2;
  endfunction

  // keep: the per-lane copies hold the same bits, which Yosys' opt_merge would merge back
  // into one register feeding every lane's multipliers
  (* keep *) always_ff @(posedge clk) begin
    if (en) begin
      for (int ch = 0; ch < NUM_CH; ch++) begin
        for (int i = 0; i < NCF; i++) cf2_q[ch * NCF + i] <= cf1_q[i];
      end
    end
  end

  // ---------------------------------------------------------------- stage 5: round, sat
  // The overflow flag is registered per lane (ovl5_q: the lane's rounded product saturated)
  // beside the input's flag (ovi5_q) and OR-ed after the registers: out_ov is the same bit in
  // the same cycle, and no path runs from the rounding's carry chains through an OR of every
  // lane (the lanes are placed far apart) into one register.
  logic [DW-1:0]     y_d, y5_q;
  logic [NUM_CH-1:0] y_ov, ovl5_q;
  logic              ovi5_q;

  // Products (stage 3) and the exact sums yr = re*C + im*S, yi = im*C - re*S (forward;
  // the inverse has S -> -S), full precision before the rounding (stage 4): two forms,
  // same bits.
  logic signed [PRW+1:0] yr_full [NUM_CH], yi_full [NUM_CH];
  logic signed [PRW+1:0] yr4_q [NUM_CH], yi4_q [NUM_CH];

  if (GAUSS) begin : g_gauss
    // Three real products per lane (Gauss): with d = -S (forward) or +S (inverse)
    //   k1 = C*(re + im), k2 = re*(d - C), k3 = im*(-C - d), yr = k1 + k3, yi = k1 + k2.
    // |C +- S| <= 92682 < 2^17, so both coefficient sums stay COEF_W bits (one per twiddle,
    // shared by every lane); the data pre-add re + im is W+1 <= 27 bits (DSP48E2 A port).
    // Both sums are additions of a product to k1 (k3 takes the negated coefficient), the form
    // a DSP48E2 post-adder with its P register takes (C port = k1).
    logic signed [COEF_W:0]   cc, ss;

    assign cc = (COEF_W+1)'(signed'(cos2_q));
    assign ss = (COEF_W+1)'(signed'(sin2_q));

    always_ff @(posedge clk) begin
      if (en) begin
        cf1_q[0] <= signed'(cos2_q);                           // C
        cf1_q[1] <= COEF_W'(INVERSE ? ss - cc : -ss - cc);     // d - C
        cf1_q[2] <= COEF_W'(INVERSE ? -cc - ss : ss - cc);     // -C - d
      end
    end

    if (!SPLIT) begin : g_mul
      logic signed [PRW:0]      k1_q [NUM_CH];
      logic signed [PRW-1:0]    k2_q [NUM_CH];
      logic signed [PRW-1:0]    k3_q [NUM_CH];

      always_ff @(posedge clk) begin
        if (en) begin
          for (int ch = 0; ch < NUM_CH; ch++) begin
            k1_q[ch] <= (PRW+1)'(a2_q[ch]) * (PRW+1)'(cf2_q[ch*NCF]);
            k2_q[ch] <= PRW'(signed'(d2_q[ch*2*W +: W])) * PRW'(cf2_q[ch*NCF + 1]);
            k3_q[ch] <= PRW'(signed'(d2_q[ch*2*W + W +: W])) * PRW'(cf2_q[ch*NCF + 2]);
          end
        end
      end

      always_comb begin
        for (int ch = 0; ch < NUM_CH; ch++) begin
          yr_full[ch] = (PRW+2)'(k1_q[ch]) + (PRW+2)'(k3_q[ch]);
          yi_full[ch] = (PRW+2)'(k1_q[ch]) + (PRW+2)'(k2_q[ch]);
        end
      end
    end
  end else begin : g_four
    // Four real products per lane (W = 27: the pre-add would not fit the 27-bit A port).
    always_ff @(posedge clk) begin
      if (en) begin
        cf1_q[0] <= signed'(cos2_q);   // C
        cf1_q[1] <= signed'(sin2_q);   // S
      end
    end

    if (!SPLIT) begin : g_mul
      logic signed [PRW-1:0] prc_r_q [NUM_CH];   // re*C
      logic signed [PRW-1:0] prs_i_q [NUM_CH];   // im*S
      logic signed [PRW-1:0] prc_i_q [NUM_CH];   // im*C
      logic signed [PRW-1:0] prs_r_q [NUM_CH];   // re*S

      always_ff @(posedge clk) begin
        if (en) begin
          for (int ch = 0; ch < NUM_CH; ch++) begin
            prc_r_q[ch] <= PRW'(signed'(d2_q[ch*2*W +: W])) * PRW'(cf2_q[ch*NCF]);
            prs_i_q[ch] <= PRW'(signed'(d2_q[ch*2*W + W +: W])) * PRW'(cf2_q[ch*NCF + 1]);
            prc_i_q[ch] <= PRW'(signed'(d2_q[ch*2*W + W +: W])) * PRW'(cf2_q[ch*NCF]);
            prs_r_q[ch] <= PRW'(signed'(d2_q[ch*2*W +: W])) * PRW'(cf2_q[ch*NCF + 1]);
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
  end

  if (SPLIT) begin : g_split
    // Products p of lane ch at ch * NP + p, each (h << LO_W) + l from its data operand's low
    // (l) and high (h) parts, both registered; the sums as in g_gauss / g_four. The operand
    // and coefficient of product p: split_op and split_cf.
    localparam int NP = GAUSS ? 3 : 4;
    logic signed [LPW-1:0] l_q [NUM_CH * NP];
    logic signed [HPW-1:0] h_q [NUM_CH * NP];

    always_ff @(posedge clk) begin
      logic signed [XW-1:0]     x;
      logic signed [COEF_W-1:0] c;
      if (en) begin
        for (int ch = 0; ch < NUM_CH; ch++) begin
          for (int p = 0; p < NP; p++) begin
            x = split_op(p) == OP_PRE ? XW'(a2_q[ch])
              : XW'(signed'(d2_q[ch*2*W + (split_op(p) == OP_IM ? W : 0) +: W]));
            c = cf2_q[ch*NCF + split_cf(p)];
            l_q[ch*NP + p] <= LPW'(signed'({1'b0, x[LO_W-1:0]})) * LPW'(c);
            h_q[ch*NP + p] <= HPW'(signed'(x[XW-1:LO_W])) * HPW'(c);
          end
        end
      end
    end

    // the partial products sign-extended to the sums' width
    logic signed [PRW+1:0] h [NUM_CH * NP], l [NUM_CH * NP];
    always_comb begin
      for (int i = 0; i < NUM_CH * NP; i++) begin
        h[i] = (PRW+2)'(h_q[i]);
        l[i] = (PRW+2)'(l_q[i]);
      end
    end

    always_comb begin
      for (int ch = 0; ch < NUM_CH; ch++) begin
        if (GAUSS) begin     // yr = k1 + k3, yi = k1 + k2
          yr_full[ch] = ((h[ch*NP] + h[ch*NP + 2]) <<< LO_W) + l[ch*NP] + l[ch*NP + 2];
          yi_full[ch] = ((h[ch*NP] + h[ch*NP + 1]) <<< LO_W) + l[ch*NP] + l[ch*NP + 1];
        end else if (INVERSE) begin
          yr_full[ch] = ((h[ch*NP] - h[ch*NP + 1]) <<< LO_W) + l[ch*NP] - l[ch*NP + 1];
          yi_full[ch] = ((h[ch*NP + 2] + h[ch*NP + 3]) <<< LO_W) + l[ch*NP + 2] + l[ch*NP + 3];
        end else begin
          yr_full[ch] = ((h[ch*NP] + h[ch*NP + 1]) <<< LO_W) + l[ch*NP] + l[ch*NP + 1];
          yi_full[ch] = ((h[ch*NP + 2] - h[ch*NP + 3]) <<< LO_W) + l[ch*NP + 2] - l[ch*NP + 3];
        end
      end
    end
  end

  always_ff @(posedge clk) begin
    if (en) begin
      d1_q     <= in_data;
      d2_q     <= d1_q;
      for (int ch = 0; ch < NUM_CH; ch++) begin
        a1_q[ch] <= (W+1)'(signed'(in_data[ch*2*W +: W]))
                  + (W+1)'(signed'(in_data[ch*2*W + W +: W]));
        a2_q[ch] <= a1_q[ch];
      end
      pos_q[0] <= in_pos;
      ov_q[0]  <= in_ov;
      for (int k = 1; k < 5; k++) pos_q[k] <= pos_q[k-1];
      for (int k = 1; k < 4; k++) ov_q[k] <= ov_q[k-1];
      for (int ch = 0; ch < NUM_CH; ch++) begin
        yr4_q[ch] <= yr_full[ch];
        yi4_q[ch] <= yi_full[ch];
      end
      y5_q     <= y_d;
      ovi5_q   <= ov_q[3];
      ovl5_q   <= y_ov;
    end
  end

  always_comb begin
    logic signed [63:0] yr, yi;
    y_d  = '0;
    y_ov = '0;
    for (int ch = 0; ch < NUM_CH; ch++) begin
      yr = fft_pkg::round_conv(64'(yr4_q[ch]), COEF_FRAC);
      yi = fft_pkg::round_conv(64'(yi4_q[ch]), COEF_FRAC);
      y_ov[ch] = fft_pkg::sat_ov(yr, W, Y_W) | fft_pkg::sat_ov(yi, W, Y_W);
      y_d[ch*2*W +: W]     = W'(fft_pkg::sat_val(yr, W, Y_W));
      y_d[ch*2*W + W +: W] = W'(fft_pkg::sat_val(yi, W, Y_W));
    end
  end

  always_ff @(posedge clk) begin
    if (rst) begin
      vld_q <= '0;
    end else if (en) begin
      vld_q <= {vld_q[3:0], in_vld};
    end
  end

  assign out_data = y5_q;
  assign out_vld  = vld_q[4];
  assign out_pos  = pos_q[4];
  assign out_ov   = ovi5_q | (|ovl5_q);
endmodule

`default_nettype wire
