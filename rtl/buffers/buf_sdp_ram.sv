// SPDX-License-Identifier: Apache-2.0
// Simple dual-port RAM (one write port, one read port, one clock) with a registered read,
// written so Vivado/Yosys infer block RAM or UltraRAM; read-during-write returns old data.
// OUT_REG = 1 registers the read data once more (the BRAM/URAM output register): two clocks
// from rd_en to rd_data, and no logic between the RAM's clock-to-out and a register.
// BANKS > 1 (OUT_REG = 1 only; for mappings whose RAM output register synthesis does not use,
// e.g. Yosys' ECP5 DP16KD): the array is split by the top log2(BANKS) address bits into BANKS
// memories, each read on rd_en at the low address bits and its read data registered (the
// OUT_REG stage, per bank); the bank is chosen after that register by the read's top address
// bits, delayed to match. So the logic that joins the RAM primitives of a deep memory (the
// depth-cascade multiplexer) sits after the output register, not between the RAM's
// clock-to-out and a register. Latency, the held output and read-during-write are those of
// BANKS = 1, cycle by cycle (formal/buf_sdp_ram.sby proves it at DEPTH 8).
`default_nettype none

module buf_sdp_ram #(
  // Word width in bits, 1..4096.
  parameter int WIDTH = 32,
  // Number of words, 2..2^24.
  parameter int DEPTH = 1024,
  // 1: output register (read latency 2 clocks), 0: read latency 1 clock.
  parameter bit OUT_REG = 0,
  // Memories the array is split into by the top address bits, each with its own output
  // register, the bank chosen after it: 1 (one array), or with OUT_REG = 1 and DEPTH a power
  // of two, a power of two 2..DEPTH/2. Same ports, latency and data as 1.
  parameter int BANKS = 1,
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
  if (BANKS < 1 || BANKS > (1 << 23) || (1 << $clog2(BANKS)) != BANKS) begin : g_bad_banks
    $fatal(1, "%m: BANKS=%0d must be a power of two", BANKS);
  end
  if (BANKS > 1 && !OUT_REG) begin : g_bad_banks_out_reg
    $fatal(1, "%m: BANKS=%0d > 1 needs OUT_REG = 1 (the per-bank output register)", BANKS);
  end
  if (BANKS > 1 && ((1 << ADDR_W) != DEPTH || DEPTH / BANKS < 2)) begin : g_bad_banks_depth
    $fatal(1, "%m: BANKS=%0d > 1 needs a power-of-two DEPTH (%0d) and DEPTH/BANKS >= 2",
           BANKS, DEPTH);
  end

`ifdef F_BUF_SDP_RAM
  // Formal (formal/buf_sdp_ram.sby, prove tasks): any address (the solver's pick, f_addr)
  // reads back the data last written to it, the old data on a write in the read's clock, held
  // while no read is issued. The asserts inside g_flat / g_banked make it inductive.
  (* anyconst *) logic [ADDR_W-1:0] f_addr;
  logic             f_wr = 1'b0;                 // f_addr written since the start
  logic [WIDTH-1:0] f_data;                      // its last written data
  logic             f_r1 = 1'b0, f_r2 = 1'b0;    // the read in rd_q / out_q: of f_addr, written
  logic [WIDTH-1:0] f_e1, f_e2;                  // and its expected data
  always_ff @(posedge clk) begin
    if (wr_en && wr_addr == f_addr) begin
      f_wr   <= 1'b1;
      f_data <= wr_data;
    end
    if (rd_en) begin
      f_r1 <= f_wr && rd_addr == f_addr;
      f_e1 <= f_data;
    end
    f_r2 <= f_r1;
    f_e2 <= f_e1;
  end
  always_comb begin
    if (OUT_REG ? f_r2 : f_r1) assert (rd_data == (OUT_REG ? f_e2 : f_e1));
  end
`endif

  if (BANKS == 1) begin : g_flat
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

`ifdef F_BUF_SDP_RAM
    always_comb begin
      if (f_wr) assert (mem_q[f_addr] == f_data);
      if (f_r1) assert (rd_q == f_e1);
    end
`endif

    if (OUT_REG) begin : g_out_reg
      logic [WIDTH-1:0] out_q;
      always_ff @(posedge clk) out_q <= rd_q;
      assign rd_data = out_q;
    end else begin : g_no_out_reg
      assign rd_data = rd_q;
    end
  end else begin : g_banked
    localparam int BANK_W = $clog2(BANKS);      // bank-select (top address) bits
    localparam int LO_W   = ADDR_W - BANK_W;    // address bits within a bank
    localparam int BANK_D = DEPTH / BANKS;      // words per bank (2^LO_W)

    logic [BANK_W-1:0] wr_hi, rd_hi;
    logic [LO_W-1:0]   wr_lo, rd_lo;
    assign {wr_hi, wr_lo} = wr_addr;
    assign {rd_hi, rd_lo} = rd_addr;

    logic [WIDTH-1:0]  bank_out [BANKS];  // per-bank output registers
    logic [BANK_W-1:0] sel1_q, sel2_q;    // the read's bank (below)

    for (genvar b = 0; b < BANKS; b++) begin : g_bank
      // As g_flat: no reset on the array or the read register (mapped into the RAM
      // primitive); out_q is the output register, in the fabric where synthesis does not
      // use the primitive's own.
      (* ram_style = "auto" *) logic [WIDTH-1:0] mem_q [BANK_D];

      always_ff @(posedge clk) begin
        if (wr_en && wr_hi == BANK_W'(b)) mem_q[wr_lo] <= wr_data;
      end

      logic [WIDTH-1:0] rd_q, out_q;
      always_ff @(posedge clk) begin
        if (rd_en) rd_q <= mem_q[rd_lo];
      end
      always_ff @(posedge clk) out_q <= rd_q;
      assign bank_out[b] = out_q;

`ifdef F_BUF_SDP_RAM
      always_comb begin
        if (f_wr && f_addr[ADDR_W-1 -: BANK_W] == BANK_W'(b))
          assert (mem_q[f_addr[LO_W-1:0]] == f_data);
        if (f_r1 && sel1_q == BANK_W'(b)) assert (rd_q == f_e1);
        if (f_r2 && sel2_q == BANK_W'(b)) assert (out_q == f_e2);
      end
`endif
    end

    // The read's bank: taken with the read (held like rd_q while no read is issued), then
    // delayed one clock like out_q; chooses among the output registers.
    always_ff @(posedge clk) begin
      if (rd_en) sel1_q <= rd_hi;
      sel2_q <= sel1_q;
    end
    assign rd_data = bank_out[sel2_q];

`ifdef F_BUF_SDP_RAM
    always_comb begin
      if (f_r1) assert (sel1_q == f_addr[ADDR_W-1 -: BANK_W]);
      if (f_r2) assert (sel2_q == f_addr[ADDR_W-1 -: BANK_W]);
    end
`endif
  end

endmodule

`default_nettype wire
