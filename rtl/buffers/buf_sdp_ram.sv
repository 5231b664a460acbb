// SPDX-License-Identifier: Apache-2.0
// Simple dual-port RAM (one write port, one read port, one clock) with a registered read,
// written so Vivado/Yosys infer block RAM or UltraRAM; read-during-write returns old data.
// OUT_REG = 1 registers the read data once more (the BRAM/URAM output register): two clocks
// from rd_en to rd_data, and no logic between the RAM's clock-to-out and a register.
`default_nettype none

module buf_sdp_ram #(
  // Word width in bits, 1..4096.
  parameter int WIDTH = 32,
  // Number of words, 2..2^24.
  parameter int DEPTH = 1024,
  // 1: output register (read latency 2 clocks), 0: read latency 1 clock.
  parameter bit OUT_REG = 0,
  // Address width in bits (derived, do not override).
  parameter int ADDR_W = $clog2(DEPTH)
) (
  input  wire logic              clk,
  // Write port
  input  wire logic              wr_en,
  input  wire logic [ADDR_W-1:0] wr_addr,
  input  wire logic [WIDTH-1:0]  wr_data,
  // Read port: rd_data is valid 1 + OUT_REG clocks after rd_en (registered read; held while
  // no read is issued)
  input  wire logic              rd_en,
  input  wire logic [ADDR_W-1:0] rd_addr,
  output logic      [WIDTH-1:0]  rd_data
);

  // Parameter checks: stop elaboration on illegal values.
  if (WIDTH < 1 || WIDTH > 4096) begin : g_bad_width
    $fatal(1, "%m: WIDTH=%0d out of range 1..4096", WIDTH);
  end
  if (DEPTH < 2 || DEPTH > (1 << 24)) begin : g_bad_depth
    $fatal(1, "%m: DEPTH=%0d out of range 2..2^24", DEPTH);
  end
  if (ADDR_W != $clog2(DEPTH)) begin : g_bad_addr_w
    $fatal(1, "%m: ADDR_W must equal $clog2(DEPTH)");
  end

  // No reset on the array or the read register: lets synthesis map both into the RAM
  // primitive (the read register becomes the BRAM/URAM output register).
  (* ram_style = "auto" *) logic [WIDTH-1:0] mem_q [DEPTH];

  always_ff @(posedge clk) begin
    if (wr_en) mem_q[wr_addr] <= wr_data;
  end

  logic [WIDTH-1:0] rd_q;
  always_ff @(posedge clk) begin
    if (rd_en) rd_q <= mem_q[rd_addr];
  end

  if (OUT_REG) begin : g_out_reg
    logic [WIDTH-1:0] out_q;
    always_ff @(posedge clk) out_q <= rd_q;
    assign rd_data = out_q;
  end else begin : g_no_out_reg
    assign rd_data = rd_q;
  end

endmodule

`default_nettype wire
