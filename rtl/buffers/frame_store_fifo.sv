// SPDX-License-Identifier: Apache-2.0
// Synchronous first-word-fall-through FIFO with AXI4-Stream handshakes on both sides (the
// frame store's write-data queue between the range FFT and the AXI4 W channel).
`default_nettype none

module frame_store_fifo #(
  // Entry width in bits, 1..4096.
  parameter int WIDTH = 32,
  // Entries, power of two, 2..4096.
  parameter int DEPTH = 16
) (
  input  wire logic             clk,
  input  wire logic             rst,
  // Sink
  input  wire logic [WIDTH-1:0] s_axis_tdata,
  input  wire logic             s_axis_tvalid,
  output logic                  s_axis_tready,
  // Source
  output logic      [WIDTH-1:0] m_axis_tdata,
  output logic                  m_axis_tvalid,
  input  wire logic             m_axis_tready
);

  localparam int PTR_W = $clog2(DEPTH);

  // Parameter checks: stop elaboration on illegal values.
  if (WIDTH < 1 || WIDTH > 4096) begin : g_bad_width
    $fatal(1, "frame_store_fifo (%m): WIDTH=%0d not in 1..4096", WIDTH);
  end
  if (DEPTH < 2 || DEPTH > 4096 || (1 << PTR_W) != DEPTH) begin : g_bad_depth
    $fatal(1, "frame_store_fifo (%m): DEPTH=%0d must be a power of two in 2..4096", DEPTH);
  end

  logic [WIDTH-1:0] mem_q [DEPTH];
  logic [PTR_W-1:0] wr_ptr_q, rd_ptr_q;
  logic [PTR_W:0]   count_q;
  logic             push, pop;

  assign s_axis_tready = !rst && (count_q != (PTR_W+1)'(DEPTH));
  assign m_axis_tvalid = (count_q != '0);
  assign m_axis_tdata  = mem_q[rd_ptr_q];
  assign push          = s_axis_tvalid && s_axis_tready;
  assign pop           = m_axis_tvalid && m_axis_tready;

  always_ff @(posedge clk) begin
    if (push) mem_q[wr_ptr_q] <= s_axis_tdata;
  end

  always_ff @(posedge clk) begin
    if (rst) begin
      wr_ptr_q <= '0;
      rd_ptr_q <= '0;
      count_q  <= '0;
    end else begin
      if (push) wr_ptr_q <= wr_ptr_q + 1'b1;
      if (pop)  rd_ptr_q <= rd_ptr_q + 1'b1;
      count_q <= count_q + (PTR_W+1)'(push) - (PTR_W+1)'(pop);
    end
  end

endmodule

`default_nettype wire
