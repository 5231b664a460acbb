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

  // True when v does not fit a w-bit two's complement number, i.e. v > 2^(w-1) - 1 or
  // v < -2^(w-1): its bits w-1..63 are not all equal (bit tests, no magnitude comparator:
  // a comparator against the limits would be a carry chain after the rounding's).
  function automatic logic sat_ov(input logic signed [63:0] v, input int unsigned w);
    logic [63:0] top;
    top = v >>> (w - 1);
    sat_ov = (top != '0) && (top != '1);
  endfunction

  // v clipped to the w-bit two's complement range (result in the low w bits): the limit of
  // v's sign when it does not fit.
  function automatic logic signed [63:0] sat_val(input logic signed [63:0] v,
                                                 input int unsigned w);
    if (!sat_ov(v, w)) sat_val = v;
    else if (v[63]) sat_val = -(64'sd1 <<< (w - 1));
    else sat_val = (64'sd1 <<< (w - 1)) - 64'sd1;
  endfunction
endpackage

`default_nettype wire
