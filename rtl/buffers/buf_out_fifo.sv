// SPDX-License-Identifier: Apache-2.0
// Small register FIFO that turns a fixed-latency read pipeline into an AXI4-Stream source:
// issue a read only when can_issue, its data arrives on in_data LATENCY clocks later.
`default_nettype none

module buf_out_fifo #(
  // Width of one entry in bits (data plus sideband), 1..8192.
  parameter int WIDTH = 32,
  // Entries, power of two, 4..64. DEPTH >= LATENCY + 2 sustains one word per clock with
  // can_issue taken from registers only (no combinational path from m_axis_tready to the
  // read enable).
  parameter int DEPTH = 4,
  // Clocks from issue to in_data, 1..32 (2 for a block RAM with its output registered).
  parameter int LATENCY = 1
) (
  input  wire logic             clk,
  input  wire logic             rst,
  // Read pipeline side
  output logic                  can_issue,  // room for one more read in flight
  input  wire logic             issue,      // a read was issued this clock (only if can_issue)
  input  wire logic [WIDTH-1:0] in_data,    // data of the read issued LATENCY clocks ago
  // AXI4-Stream source (tdata carries the whole entry, the parent splits it)
  output logic      [WIDTH-1:0] m_axis_tdata,
  output logic                  m_axis_tvalid,
  input  wire logic             m_axis_tready
);

  localparam int PTR_W = $clog2(DEPTH);

  // Parameter checks: stop elaboration on illegal values.
  if (DEPTH < 4 || DEPTH > 64 || (1 << PTR_W) != DEPTH) begin : g_bad_depth
    $fatal(1, "%m: DEPTH=%0d must be a power of two in 4..64", DEPTH);
  end
  if (WIDTH < 1 || WIDTH > 8192) begin : g_bad_width
    $fatal(1, "%m: WIDTH=%0d out of range", WIDTH);
  end
  if (LATENCY < 1 || LATENCY > 32) begin : g_bad_latency
    $fatal(1, "%m: LATENCY=%0d out of range 1..32", LATENCY);
  end

  logic [WIDTH-1:0] mem_q [DEPTH];
  logic [PTR_W-1:0] wr_ptr_q, rd_ptr_q;
  logic [PTR_W:0]   count_q;        // entries stored
  logic [PTR_W:0]   credit_q;       // entries stored + reads in flight
  logic [LATENCY-1:0] inflight_q;   // bit k: a read was issued k+1 clocks ago
  logic             push, pop;

  assign push          = inflight_q[LATENCY-1];
  assign pop           = m_axis_tvalid && m_axis_tready;
  assign m_axis_tvalid = (count_q != '0);
  assign m_axis_tdata  = mem_q[rd_ptr_q];
  assign can_issue     = (credit_q < (PTR_W+1)'(DEPTH));

  always_ff @(posedge clk) begin
    if (push) mem_q[wr_ptr_q] <= in_data;
  end

  always_ff @(posedge clk) begin
    if (rst) begin
      wr_ptr_q   <= '0;
      rd_ptr_q   <= '0;
      count_q    <= '0;
      credit_q   <= '0;
      inflight_q <= '0;
    end else begin
      inflight_q <= (inflight_q << 1) | LATENCY'(issue);
      if (push) wr_ptr_q <= wr_ptr_q + 1'b1;
      if (pop)  rd_ptr_q <= rd_ptr_q + 1'b1;
      count_q  <= count_q + (PTR_W+1)'(push) - (PTR_W+1)'(pop);
      credit_q <= credit_q + (PTR_W+1)'(issue) - (PTR_W+1)'(pop);
    end
  end

`ifdef FORMAL
  // Formal properties (formal/buf_out_fifo.sby; also checked inside every parent's proof).
  // Credit: stored + in flight == issued - popped, never above DEPTH; pointers differ by the
  // count; the output port obeys AXI-Stream (rtl/common/axis_checker.sv).
  logic f_past = 1'b0;
  logic [7:0] f_issued = '0, f_popped = '0;
  always_ff @(posedge clk) begin
    f_past <= 1'b1;
    if (rst) begin
      f_issued <= '0;
      f_popped <= '0;
    end else begin
      f_issued <= f_issued + 8'(issue);
      f_popped <= f_popped + 8'(pop);
    end
  end
`ifdef F_TOP_BUF_OUT_FIFO
  initial assume (rst);
  always_comb if (!rst) assume (!issue || can_issue);
`endif
  logic [PTR_W:0] f_inflight;
  always_comb begin
    f_inflight = '0;
    for (int k = 0; k < LATENCY; k++) f_inflight = f_inflight + (PTR_W+1)'(inflight_q[k]);
  end
  always_comb if (f_past && !rst) begin
    assert (!issue || can_issue);
    assert (count_q <= (PTR_W+1)'(DEPTH));
    assert (credit_q == count_q + f_inflight);
    assert (credit_q == (PTR_W+1)'(f_issued - f_popped));
    assert (PTR_W'(wr_ptr_q - rd_ptr_q) == count_q[PTR_W-1:0]);
  end
  always_comb if (f_past && !rst) begin
    cover (count_q == (PTR_W+1)'(DEPTH));
    cover (pop && push && count_q == (PTR_W+1)'(1));
  end
  axis_checker #(.PAYLOAD_W(WIDTH)) f_chk_m_axis (
    .clk, .rst, .tvalid(m_axis_tvalid), .tready(m_axis_tready), .payload(m_axis_tdata));
`endif

`ifdef FORMAL
  // (the FORMAL block above states this property for the proof)
`elsif SYNTHESIS
`else
  always_ff @(posedge clk) begin
    if (!rst) begin
      assert (!(issue && !can_issue)) else $error("buf_out_fifo: read issued without credit");
      assert (!(push && count_q == (PTR_W+1)'(DEPTH))) else $error("buf_out_fifo: overflow");
    end
  end
`endif

endmodule

`default_nettype wire
