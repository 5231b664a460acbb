// SPDX-License-Identifier: Apache-2.0
// Input stage of the streaming FFT: widens each I/Q sample to the internal format
// (GUARD_W fraction bits) and, with WINDOW = 1, multiplies it by the periodic Hann window
// of N_IN points from fft_win_rom (the quarter-wave fft_hann_rom when N_IN is a power of two;
// convergent rounding). The multiplier is registered on both sides the way a DSP48E2 (AREG/BREG,
// MREG) or an ECP5 MULT18X18D wants it: operands registered twice (the first register beside the
// ROM and the input select, the second beside the multiplier: a long route to a free multiplier
// column is a whole clock), the exact product registered, then rounded into the output register.
// Four register stages with the window: operands; operands at the multiplier; product; rounded.
`default_nettype none

module fft_window #(
  // Lanes processed in parallel, 1..16.
  parameter int NUM_CH = 1,
  // Input bits of I and of Q, 8..24.
  parameter int DATA_W = 16,
  // Fraction bits added inside the pipeline, 0..16.
  parameter int GUARD_W = 4,
  // Internal bits of I and of Q (>= DATA_W + GUARD_W).
  parameter int W = 21,
  // log2 of the transform length, 4..12.
  parameter int LOG2N = 6,
  // 0: no window (1 advance of latency); 1: periodic Hann (4 advances).
  parameter bit WINDOW = 0,
  // Window length: the samples of a vector (positions 0..N_IN-1), 2..2^LOG2N; the zero fill
  // behind them is zero whatever it is multiplied by.
  parameter int N_IN = 1 << LOG2N
) (
  input  logic clk,
  input  logic rst,
  // Pipeline advance.
  input  logic en,
  // Sample in (DATA_W per component).
  input  logic [NUM_CH*2*DATA_W-1:0] in_data,
  input  logic                       in_vld,
  input  logic [LOG2N-1:0]           in_pos,
  // Sample out (W per component).
  output logic [NUM_CH*2*W-1:0]      out_data,
  output logic                       out_vld,
  output logic [LOG2N-1:0]           out_pos
);
  // coefficient ROM geometry (rtl/fft/fft_rom_pkg.sv, generated)
  localparam int ROM_LOG2 = fft_rom_pkg::ROM_LOG2;
  localparam int COEF_W = fft_rom_pkg::COEF_W;
  localparam int COEF_FRAC = fft_rom_pkg::COEF_FRAC;

  localparam int DW = NUM_CH * 2 * W;

  if (W < DATA_W + GUARD_W || GUARD_W > COEF_FRAC || LOG2N > ROM_LOG2) begin : g_bad_guard_w
    $fatal(1, "%m: need W >= DATA_W+GUARD_W, GUARD_W <= 16 (GUARD_W=%0d)", GUARD_W);
  end

  if (WINDOW) begin : g_win
    localparam int PW = DATA_W + COEF_W;   // exact product width
    logic [NUM_CH*2*DATA_W-1:0] d1_q, d2_q;
    logic [LOG2N-1:0]           pos_q [4];
    logic [3:0]                 vld_q;
    logic signed [COEF_W-1:0]   w1_q, w2_q;
    logic signed [PW-1:0]       p3_q [2*NUM_CH];
    logic [DW-1:0]              y_d, y4_q;
    logic [ROM_LOG2-1:0]        rom_idx;
    logic [COEF_W-1:0]          rom_hann;

    assign rom_idx = ROM_LOG2'(in_pos);
    // the N_IN-point window (generated, combinational)
    fft_win_rom #(.N(N_IN)) u_rom (.k(rom_idx), .w_o(rom_hann));

    always_comb begin
      y_d = '0;
      for (int c = 0; c < 2 * NUM_CH; c++) begin
        // |x * w| <= |x| so the result always fits: no saturation needed.
        y_d[c*W +: W] = W'(fft_pkg::round_conv(64'(p3_q[c]), COEF_FRAC - GUARD_W));
      end
    end

    always_ff @(posedge clk) begin
      if (en) begin
        d1_q     <= in_data;
        w1_q     <= signed'(rom_hann);
        d2_q     <= d1_q;
        w2_q     <= w1_q;
        for (int c = 0; c < 2 * NUM_CH; c++) begin
          p3_q[c] <= PW'(signed'(d2_q[c*DATA_W +: DATA_W])) * PW'(w2_q);
        end
        y4_q     <= y_d;
        pos_q[0] <= in_pos;
        for (int k = 1; k < 4; k++) pos_q[k] <= pos_q[k-1];
      end
    end

    always_ff @(posedge clk) begin
      if (rst) begin
        vld_q <= '0;
      end else if (en) begin
        vld_q <= {vld_q[2:0], in_vld};
      end
    end

    assign out_data = y4_q;
    assign out_vld  = vld_q[3];
    assign out_pos  = pos_q[3];
  end else begin : g_nowin
    logic [DW-1:0]    y_d, y1_q;
    logic [LOG2N-1:0] pos1_q;
    logic             vld1_q;

    always_comb begin
      y_d = '0;
      for (int c = 0; c < 2 * NUM_CH; c++) begin
        y_d[c*W +: W] = W'(signed'(in_data[c*DATA_W +: DATA_W])) <<< GUARD_W;
      end
    end

    always_ff @(posedge clk) begin
      if (en) begin
        y1_q   <= y_d;
        pos1_q <= in_pos;
      end
    end

    always_ff @(posedge clk) begin
      if (rst) begin
        vld1_q <= 1'b0;
      end else if (en) begin
        vld1_q <= in_vld;
      end
    end

    assign out_data = y1_q;
    assign out_vld  = vld1_q;
    assign out_pos  = pos1_q;
  end
endmodule

`default_nettype wire
