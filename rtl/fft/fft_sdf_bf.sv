// SPDX-License-Identifier: Apache-2.0
// One radix-2 single-path delay-feedback (SDF) butterfly stage of the streaming FFT, with the
// radix-2^2 trivial -j rotation (BF-II), optional 1/2 scaling, convergent rounding and
// saturation. Every sample carries a tag (valid, index in frame, overflow) that travels with
// it through the delay line, so the stage is controlled by the data it holds.
`default_nettype none

module fft_sdf_bf #(
  // Lanes (channels) processed in parallel, 1..16.
  parameter int NUM_CH = 1,
  // Bits of I and of Q inside the pipeline, 8..27.
  parameter int W = 21,
  // log2 of the transform length, 4..12 (width of the sample index tag).
  parameter int LOG2N = 6,
  // Butterfly span in samples (delay line length), power of two, 1..2^(LOG2N-1).
  parameter int D = 32,
  // 1: BF-II stage (multiply the second input by -j when index bit log2(2D) is set).
  parameter bit ROTATE = 0,
  // 1: inverse transform (+j instead of -j).
  parameter bit INVERSE = 0,
  // 1: divide both butterfly outputs by 2 (convergent rounding).
  parameter bit SCALE = 1
) (
  input  logic clk,
  input  logic rst,
  // Pipeline advance: every register and the delay line move only when en is high.
  input  logic en,
  // Sample in.
  input  logic [NUM_CH*2*W-1:0] in_data,
  input  logic                  in_vld,
  input  logic [LOG2N-1:0]      in_pos,
  input  logic                  in_ov,
  // Sample out (registered), same order as the input, D+1 advances later.
  output logic [NUM_CH*2*W-1:0] out_data,
  output logic                  out_vld,
  output logic [LOG2N-1:0]      out_pos,
  output logic                  out_ov
);

  localparam int DW = NUM_CH * 2 * W;
  localparam int MW = DW + LOG2N + 1;         // delay line word: data, index, overflow
  localparam int DB = $clog2(D);              // index bit selecting the butterfly half
  localparam int PW = (D > 1) ? $clog2(D) : 1;

  if (D < 1 || (1 << DB) != D || DB >= LOG2N) begin : g_bad_d
    $fatal(1, "%m: D=%0d must be a power of two below 2^LOG2N", D);
  end
  if (ROTATE && DB + 1 >= LOG2N) begin : g_bad_rotate
    $fatal(1, "%m: ROTATE needs D <= 2^(LOG2N-2) (D=%0d)", D);
  end

  // ---------------------------------------------------------------- delay line (FIFO of D)
  logic [MW-1:0] mem_q [D];
  logic [D-1:0]  mvld_q;
  logic [PW-1:0] ptr_q;
  logic [MW-1:0] head;
  logic          head_vld;
  logic [DW-1:0] head_data;
  logic [LOG2N-1:0] head_pos;
  logic          head_ov;

  // D >= 2: the head is prefetched into a register at the previous advance (mem[ptr+1] is
  // never the slot being written), so the delay line is a simple dual-port RAM with a
  // registered read port (block RAM / SRL friendly). D = 1: the single slot itself.
  if (D >= 2) begin : g_prefetch
    logic [MW-1:0] head_q;
    always_ff @(posedge clk) begin
      if (en) head_q <= mem_q[(ptr_q == PW'(D - 1)) ? '0 : ptr_q + 1'b1];
    end
    assign head = head_q;
  end else begin : g_direct
    assign head = mem_q[ptr_q];
  end
  assign head_vld = mvld_q[ptr_q];
  assign {head_data, head_pos, head_ov} = head;

  // ---------------------------------------------------------------- butterfly
  logic          phase;     // 0: store the input, emit the stored difference; 1: butterfly
  logic          rot;
  logic [DW-1:0] sum_data, dif_data;
  logic          sum_ov, dif_ov;

  assign phase = in_pos[DB];
  if (ROTATE) begin : g_rot
    assign rot = in_pos[DB+1];
  end else begin : g_norot
    assign rot = 1'b0;
  end

  always_comb begin
    logic signed [63:0] ar, ai, xr, xi, sr, si, dr, di;
    sum_data = '0;
    dif_data = '0;
    sum_ov   = 1'b0;
    dif_ov   = 1'b0;
    for (int ch = 0; ch < NUM_CH; ch++) begin
      ar = 64'(signed'(head_data[ch*2*W +: W]));
      ai = 64'(signed'(head_data[ch*2*W + W +: W]));
      xr = 64'(signed'(in_data[ch*2*W +: W]));
      xi = 64'(signed'(in_data[ch*2*W + W +: W]));
      if (rot) begin
        if (INVERSE) begin  // x * (+j)
          {xr, xi} = {-xi, xr};
        end else begin      // x * (-j)
          {xr, xi} = {xi, -xr};
        end
      end
      sr = fft_pkg::round_conv(ar + xr, SCALE ? 1 : 0);
      si = fft_pkg::round_conv(ai + xi, SCALE ? 1 : 0);
      dr = fft_pkg::round_conv(ar - xr, SCALE ? 1 : 0);
      di = fft_pkg::round_conv(ai - xi, SCALE ? 1 : 0);
      sum_ov = sum_ov | fft_pkg::sat_ov(sr, W) | fft_pkg::sat_ov(si, W);
      dif_ov = dif_ov | fft_pkg::sat_ov(dr, W) | fft_pkg::sat_ov(di, W);
      sum_data[ch*2*W +: W]     = W'(fft_pkg::sat_val(sr, W));
      sum_data[ch*2*W + W +: W] = W'(fft_pkg::sat_val(si, W));
      dif_data[ch*2*W +: W]     = W'(fft_pkg::sat_val(dr, W));
      dif_data[ch*2*W + W +: W] = W'(fft_pkg::sat_val(di, W));
    end
  end

  // ---------------------------------------------------------------- registers
  logic [DW-1:0]    out_data_q;
  logic [LOG2N-1:0] out_pos_q;
  logic             out_ov_q, out_vld_q;

  always_ff @(posedge clk) begin
    if (en) begin
      if (phase) begin
        out_data_q   <= sum_data;
        out_ov_q     <= head_ov | in_ov | sum_ov;
        mem_q[ptr_q] <= {dif_data, in_pos, head_ov | in_ov | dif_ov};
      end else begin
        out_data_q   <= head_data;
        out_ov_q     <= head_ov;
        mem_q[ptr_q] <= {in_data, in_pos, in_ov};
      end
      out_pos_q <= head_pos;
    end
  end

  // Valid bits and the pointer are the only reset state (the data path is not reset).
  always_ff @(posedge clk) begin
    if (rst) begin
      mvld_q    <= '0;
      out_vld_q <= 1'b0;
      ptr_q     <= '0;
    end else if (en) begin
      mvld_q[ptr_q] <= in_vld;
      out_vld_q     <= head_vld;
      ptr_q         <= (ptr_q == PW'(D - 1)) ? '0 : ptr_q + 1'b1;
    end
  end

  assign out_data = out_data_q;
  assign out_vld  = out_vld_q;
  assign out_pos  = out_pos_q;
  assign out_ov   = out_ov_q;
endmodule

`default_nettype wire
