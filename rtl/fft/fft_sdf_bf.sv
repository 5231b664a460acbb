// SPDX-License-Identifier: Apache-2.0
// One radix-2 single-path delay-feedback (SDF) butterfly stage of the streaming FFT, with the
// radix-2^2 trivial -j rotation (BF-II), optional 1/2 scaling, convergent rounding and
// saturation. Every sample carries a tag (valid, index in frame, overflow) that travels with
// it through the delay line, so the stage is controlled by the data it holds.
// Two register stages: the exact sum / difference (W+1 bits; the difference also goes into
// the delay line unrounded), then the rounding and saturation of whichever is sent on.
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
  // Sample out (registered), same order as the input, D+2 advances later.
  output logic [NUM_CH*2*W-1:0] out_data,
  output logic                  out_vld,
  output logic [LOG2N-1:0]      out_pos,
  output logic                  out_ov,
  // Index of the sample out_pos shows two advances later (the delay line's head), for a
  // twiddle that looks its coefficient up ahead of the data.
  output logic [LOG2N-1:0]      out_pos_ahead
);

  localparam int DW = NUM_CH * 2 * W;
  localparam int FW = NUM_CH * 2 * (W + 1);   // exact sums / differences
  localparam int RND_W = fft_pkg::round_w(W + 1, SCALE ? 1 : 0);   // rounded sum's bits
  localparam int MW = FW + LOG2N + 1;         // delay line word: data, index, overflow
  localparam int DB = $clog2(D);              // index bit selecting the butterfly half
  localparam int PW = (D > 1) ? $clog2(D) : 1;
  localparam int BRAM_D = 64;                 // shortest delay line read through block RAM

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
  logic [FW-1:0] head_data;   // phase 1: an input (sign-extended); phase 0: a difference
  logic [LOG2N-1:0] head_pos;
  logic          head_ov;

  // D >= 2: the head is prefetched into a register at the previous advance (mem[ptr+1] is
  // never the slot being written), so the delay line is a simple dual-port RAM with a
  // registered read port (block RAM / SRL friendly). D = 1: the single slot itself.
  // D >= BRAM_D (the lines synthesis maps to block RAM: ECP5 DP16KD, 4.3 ns clock-to-out
  // without its output register): read two advances ahead, the RAM's read register then a
  // fabric register, so no logic follows the RAM in the same cycle (mem[ptr+2] is not written
  // at this advance nor the next; same head, same latency).
  if (D >= BRAM_D) begin : g_prefetch2
    logic [MW-1:0] rd_q, head_q;
    logic [PW-1:0] rd_addr;
    assign rd_addr = ptr_q + PW'(2);   // modulo D = 2^PW
    always_ff @(posedge clk) begin
      if (en) begin
        rd_q   <= mem_q[rd_addr];
        head_q <= rd_q;
      end
    end
    assign head = head_q;
  end else if (D >= 2) begin : g_prefetch
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
  logic [FW-1:0] in_ext, sum_full, dif_full;

  assign phase = in_pos[DB];
  if (ROTATE) begin : g_rot
    assign rot = in_pos[DB+1];
  end else begin : g_norot
    assign rot = 1'b0;
  end

  // Exact a + x and a - x with x rotated by -j (+j inverse): each component is the head's
  // plus or minus one of the input's components (no separate negation).
  always_comb begin
    logic signed [W:0] ar, ai, xr, xi, ur, ui;
    logic              nr, ni;   // the rotated x's component is the negated ur / ui
    for (int ch = 0; ch < NUM_CH; ch++) begin
      ar = (W+1)'(signed'(head_data[ch*2*(W+1) +: W+1]));
      ai = (W+1)'(signed'(head_data[ch*2*(W+1) + W+1 +: W+1]));
      xr = (W+1)'(signed'(in_data[ch*2*W +: W]));
      xi = (W+1)'(signed'(in_data[ch*2*W + W +: W]));
      in_ext[ch*2*(W+1) +: W+1]       = xr;
      in_ext[ch*2*(W+1) + W+1 +: W+1] = xi;
      ur = xr;
      ui = xi;
      nr = 1'b0;
      ni = 1'b0;
      if (rot) begin
        if (INVERSE) begin  // x * (+j) = (-xi, xr)
          ur = xi;
          ui = xr;
          nr = 1'b1;
        end else begin      // x * (-j) = (xi, -xr)
          ur = xi;
          ui = xr;
          ni = 1'b1;
        end
      end
      sum_full[ch*2*(W+1) +: W+1]       = nr ? ar - ur : ar + ur;
      sum_full[ch*2*(W+1) + W+1 +: W+1] = ni ? ai - ui : ai + ui;
      dif_full[ch*2*(W+1) +: W+1]       = nr ? ar + ur : ar - ur;
      dif_full[ch*2*(W+1) + W+1 +: W+1] = ni ? ai + ui : ai - ui;
    end
  end

  // ---------------------------------------------------------------- registers
  logic [FW-1:0]    full_q;      // stage 1: exact value of the sample sent on
  logic [LOG2N-1:0] pos1_q, out_pos_q;
  logic             ov1_q, vld1_q;
  logic [DW-1:0]    out_data_q;  // stage 2: rounded, saturated
  logic             out_vld_q;
  // stage 2's overflow flag, registered per lane (out_ovl_q: the lane's re or im saturated)
  // beside stage 1's (out_ovi_q) and OR-ed after the registers: out_ov is the same bit in the
  // same cycle, without a path from every lane's rounding through one OR into one register
  logic [NUM_CH-1:0] out_ovl_q;
  logic              out_ovi_q;

  always_ff @(posedge clk) begin
    if (en) begin
      if (phase) begin
        full_q       <= sum_full;
        ov1_q        <= head_ov | in_ov;
        mem_q[ptr_q] <= {dif_full, in_pos, head_ov | in_ov};
      end else begin
        full_q       <= head_data;
        ov1_q        <= head_ov;
        mem_q[ptr_q] <= {in_ext, in_pos, in_ov};
      end
      pos1_q <= head_pos;
    end
  end

  always_ff @(posedge clk) begin
    logic signed [63:0] v;
    logic [NUM_CH-1:0]  ov;
    if (en) begin
      ov = '0;
      for (int c = 0; c < 2 * NUM_CH; c++) begin   // component c of lane c / 2 (re, im)
        v  = fft_pkg::round_conv(64'(signed'(full_q[c*(W+1) +: W+1])), SCALE ? 1 : 0);
        ov[c / 2] = ov[c / 2] | fft_pkg::sat_ov(v, W, RND_W);
        out_data_q[c*W +: W] <= W'(fft_pkg::sat_val(v, W, RND_W));
      end
      out_ovl_q <= ov;
      out_ovi_q <= ov1_q;
      out_pos_q <= pos1_q;
    end
  end

  // Valid bits and the pointer are the only reset state (the data path is not reset).
  always_ff @(posedge clk) begin
    if (rst) begin
      mvld_q    <= '0;
      vld1_q    <= 1'b0;
      out_vld_q <= 1'b0;
      ptr_q     <= '0;
    end else if (en) begin
      mvld_q[ptr_q] <= in_vld;
      vld1_q        <= head_vld;
      out_vld_q     <= vld1_q;
      ptr_q         <= (ptr_q == PW'(D - 1)) ? '0 : ptr_q + 1'b1;
    end
  end

  assign out_data = out_data_q;
  assign out_vld  = out_vld_q;
  assign out_pos  = out_pos_q;
  assign out_ov   = out_ovi_q | (|out_ovl_q);
  assign out_pos_ahead = head_pos;   // -> pos1_q -> out_pos_q
endmodule

`default_nettype wire
