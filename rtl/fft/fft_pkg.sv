// SPDX-License-Identifier: Apache-2.0
// Fixed-point helpers of the streaming FFT: convergent rounding and saturation.
// Called package-scoped (fft_pkg::round_conv(...)); results are assigned to the function
// name (no `return`) so Yosys' read_verilog -sv reads the file as written.
`default_nettype none

package fft_pkg;
  // Convergent rounding (round half to even) of v / 2^k, k >= 0. Operands are 64-bit so one
  // function serves every width; synthesis trims the unused bits at each call site.
  function automatic logic signed [63:0] round_conv(input logic signed [63:0] v,
                                                    input int unsigned k);
    logic signed [63:0] q;
    logic [63:0] mask;
    logic half, rest;
    if (k == 0) begin
      round_conv = v;
    end else begin
      q = v >>> k;
      half = v[k-1];
      mask = (64'd1 << (k - 1)) - 64'd1;
      rest = |(v & mask);
      round_conv = q + ((half && (rest || q[0])) ? 64'sd1 : 64'sd0);
    end
  endfunction

  // Bits of round_conv(v, k)'s result for an n-bit v: the quotient's n - k bits and one more
  // for the rounding increment (k = 0: v itself).
  function automatic int unsigned round_w(input int unsigned n, input int unsigned k);
    round_w = (k == 0) ? n : n - k + 1;
  endfunction

  // Whether v, an n-bit two's complement value held in 64 bits (bits n..63 copies of bit n-1),
  // lies above the w-bit range (v > 2^(w-1) - 1: sign clear, bits w-1..n-1 not all 0) or below
  // it (v < -2^(w-1): sign set, bits w-1..n-1 not all 1). Bit tests, no magnitude comparator
  // (a comparator against a limit is a carry chain after the rounding's); only bits below n
  // are read.
  function automatic logic sat_hi(input logic signed [63:0] v, input int unsigned w,
                                  input int unsigned n);
    logic [63:0] mask;
    if (n <= w) begin
      sat_hi = 1'b0;
    end else begin
      mask = (64'd1 << (n - w + 1)) - 64'd1;
      sat_hi = (((v >>> (w - 1)) & mask) != '0) && (((v >>> (n - 1)) & 64'd1) == '0);
    end
  endfunction
  function automatic logic sat_lo(input logic signed [63:0] v, input int unsigned w,
                                  input int unsigned n);
    logic [63:0] mask;
    if (n <= w) begin
      sat_lo = 1'b0;
    end else begin
      mask = (64'd1 << (n - w + 1)) - 64'd1;
      sat_lo = (((v >>> (w - 1)) & mask) != mask) && (((v >>> (n - 1)) & 64'd1) != '0);
    end
  endfunction

  // True when v (n bits, as above) does not fit w bits.
  function automatic logic sat_ov(input logic signed [63:0] v, input int unsigned w,
                                  input int unsigned n);
    sat_ov = sat_hi(v, w, n) || sat_lo(v, w, n);
  endfunction

  // v (n bits, as above) clipped to the w-bit two's complement range (result in the low w
  // bits). Each limit is a constant chosen by its own condition, so a register loading the
  // result takes the limits on its synchronous set / reset pins instead of a multiplexer.
  function automatic logic signed [63:0] sat_val(input logic signed [63:0] v,
                                                 input int unsigned w, input int unsigned n);
    if (sat_hi(v, w, n)) sat_val = (64'sd1 <<< (w - 1)) - 64'sd1;
    else if (sat_lo(v, w, n)) sat_val = -(64'sd1 <<< (w - 1));
    else sat_val = v;
  endfunction
endpackage

`default_nettype wire
