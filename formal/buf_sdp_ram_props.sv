// SPDX-License-Identifier: Apache-2.0
// Formal harness of buf_sdp_ram's BANKS option (formal/buf_sdp_ram.sby, bmc and cover): two
// instances with the same inputs, BANKS = 1 (one array, the reference) and BANKS = 4 (four
// arrays, the bank chosen after the per-bank output registers), DEPTH 8, WIDTH 2, OUT_REG 1.
//   - every read of an address written before it (f_written, kept here; a write in the read's
//     clock does not count: read-during-write returns the old data) gives the same rd_data
//     on both, from the clock it appears (two after rd_en) for as long as it is held (no
//     read issued); reads of never-written addresses are not compared: the arrays are not
//     initialised, in the design or here;
//   - the covers reach reads of all four banks, a read during a write of its address whose
//     old and new data differ, and an output held over an idle clock while the bank's array
//     was rewritten.
// The prove tasks check each configuration alone against the same behaviour, unbounded (the
// F_BUF_SDP_RAM block in rtl/buffers/buf_sdp_ram.sv).
`default_nettype none

module buf_sdp_ram_props (
  input wire logic       clk,
  input wire logic       wr_en,
  input wire logic [2:0] wr_addr,
  input wire logic [1:0] wr_data,
  input wire logic       rd_en,
  input wire logic [2:0] rd_addr
);
  localparam int DEPTH = 8, WIDTH = 2;

  logic [WIDTH-1:0] rd_data_a, rd_data_b;

  buf_sdp_ram #(.WIDTH(WIDTH), .DEPTH(DEPTH), .OUT_REG(1'b1), .BANKS(1)) dut_a (
    .clk, .wr_en, .wr_addr, .wr_data, .rd_en, .rd_addr, .rd_data(rd_data_a));
  buf_sdp_ram #(.WIDTH(WIDTH), .DEPTH(DEPTH), .OUT_REG(1'b1), .BANKS(4)) dut_b (
    .clk, .wr_en, .wr_addr, .wr_data, .rd_en, .rd_addr, .rd_data(rd_data_b));

  logic [DEPTH-1:0] f_written = '0;   // addresses written since the start
  logic             f_v1 = 1'b0;      // the last read (held in the read registers) was valid
  logic             f_v2 = 1'b0;      // ... and one clock later (the output registers)
  logic [2:0]       f_a1, f_a2;       // its address
  always_ff @(posedge clk) begin
    if (wr_en) f_written[wr_addr] <= 1'b1;
    if (rd_en) begin
      f_v1 <= f_written[rd_addr];
      f_a1 <= rd_addr;
    end
    f_v2 <= f_v1;
    f_a2 <= f_a1;
  end

  always_comb begin
    if (f_v2) assert (rd_data_a == rd_data_b);
  end

  // covers
  logic [WIDTH-1:0] f_mem [DEPTH];    // the data written (the covers' "old data")
  always_ff @(posedge clk) begin
    if (wr_en) f_mem[wr_addr] <= wr_data;
  end
  logic [3:0] f_banks = '0;           // banks whose valid read reached rd_data
  logic       f_rdw1 = 1'b0, f_rdw2 = 1'b0;   // a valid read during a write of its address,
                                              // new data != old, in flight
  logic       f_hold = 1'b0;          // a valid output held over an idle clock with a write
  always_ff @(posedge clk) begin
    if (f_v2) f_banks[f_a2[2:1]] <= 1'b1;
    f_rdw1 <= rd_en ? (f_written[rd_addr] && wr_en && wr_addr == rd_addr &&
                       wr_data != f_mem[rd_addr]) : 1'b0;
    f_rdw2 <= f_rdw1;
    f_hold <= f_v2 && !rd_en && wr_en && wr_addr == f_a2 && wr_data != f_mem[f_a2];
  end

  always_comb begin
    cover (f_banks == 4'hf);
    cover (f_rdw2 && f_v2);
    cover (f_hold && f_v2 && !rd_en);
  end

endmodule

`default_nettype wire
