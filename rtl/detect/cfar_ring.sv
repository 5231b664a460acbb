// SPDX-License-Identifier: Apache-2.0
// cfar_2d's column delay lines (docs/detect.md): what a shift register of N entries that
// shifts on en (q[0] <= d, q[k] <= q[k-1]) holds, at the positions USED names, kept in a
// ring of distributed RAM instead of N * W flip-flops. One write pointer advances on en;
// a used position k whose neighbour k-1 is not used is a register loaded on en from the ring
// entry written k enables before (address pointer - k, read while the new entry is written:
// the ring holds 2^clog2(K+1) > K entries, K the deepest such position); a used position
// whose neighbour is used is loaded from that neighbour, position 0 from d. So every q[k]
// read holds, clock by clock, the value the shift register's entry k holds. Unused
// positions are 0. No reset: the pointer's start value does not matter (every read is
// relative to it), and like the shift register the entries are defined once written.
`default_nettype none

module cfar_ring #(
  parameter int W = 43,                 // bits per entry
  parameter int N = 20,                 // shift register length
  parameter logic [N-1:0] USED = '1     // bit k: position k is read
) (
  input  wire logic               clk,
  input  wire logic               en,
  input  wire logic [W-1:0]       d,
  output logic [N-1:0][W-1:0]     q
);

  // the deepest position read from the ring (used, its neighbour k-1 not); 0: none
  // (result assigned to the function name, no `return`: Yosys reads the file as written)
  function automatic int ring_top(input logic [N-1:0] used);
    ring_top = 0;
    for (int k = 1; k < N; k++)
      if (used[k] && !used[k-1]) ring_top = k;
  endfunction
  localparam int TOP = ring_top(USED);
  localparam int A_W = (TOP > 0) ? $clog2(TOP + 1) : 1;

  logic [A_W-1:0] wp_q;
  (* ram_style = "distributed" *) logic [W-1:0] mem [1 << A_W];
  always_ff @(posedge clk)
    if (en) begin
      mem[wp_q] <= d;
      wp_q      <= wp_q + 1'b1;
    end

  for (genvar k = 0; k < N; k++) begin : g_pos
    if (!USED[k]) begin : g_unused
      assign q[k] = '0;
    end else begin : g_used
      logic [W-1:0] r_q;
      if (k == 0) begin : g_first
        always_ff @(posedge clk) if (en) r_q <= d;
      end else if (USED[(k > 0) ? k - 1 : 0]) begin : g_next
        always_ff @(posedge clk) if (en) r_q <= q[k-1];
      end else begin : g_read
        always_ff @(posedge clk) if (en) r_q <= mem[wp_q - A_W'(k)];
      end
      assign q[k] = r_q;
    end
  end

  if (TOP == 0) begin : g_no_ring
    logic unused_ring;          // every used position is a register: no ring read
    assign unused_ring = ^mem[0];
  end

endmodule

`default_nettype wire
