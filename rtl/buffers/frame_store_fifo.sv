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

`ifdef FORMAL
  // Formal properties (formal/frame_store_fifo.sby). Both ports obey AXI-Stream (the sink's
  // rules assumed, the source's asserted: rtl/common/axis_checker.sv); no beat created or
  // lost: pushes - pops == count <= DEPTH; order and contents: any word pushed (picked by
  // the solver) leaves after exactly the words ahead of it, unchanged.
  logic f_past = 1'b0;
  logic [7:0] f_in = '0, f_out = '0;
  (* anyseq *) logic f_pick;
  logic [WIDTH-1:0] f_word;
  logic [PTR_W:0] f_pos;
  logic f_track = 1'b0;
  always_ff @(posedge clk) begin
    f_past <= 1'b1;
    if (rst) begin
      f_in <= '0;
      f_out <= '0;
      f_track <= 1'b0;
    end else begin
      f_in  <= f_in + 8'(push);
      f_out <= f_out + 8'(pop);
      if (f_track && pop) begin
        if (f_pos == '0) f_track <= 1'b0;
        f_pos <= f_pos - 1'b1;
      end
      if (!f_track && push && f_pick) begin
        f_track <= 1'b1;
        f_word  <= s_axis_tdata;
        f_pos   <= count_q - (PTR_W+1)'(pop);
      end
    end
  end
`ifdef F_TOP_FRAME_STORE_FIFO
  initial assume (rst);
`endif
  always_comb if (f_past && !rst) begin
    assert (count_q <= (PTR_W+1)'(DEPTH));
    assert ((PTR_W+1)'(f_in - f_out) == count_q);
    assert (PTR_W'(wr_ptr_q - rd_ptr_q) == count_q[PTR_W-1:0]);
    if (f_track) begin
      assert (f_pos < count_q);
      assert (mem_q[PTR_W'(rd_ptr_q + f_pos[PTR_W-1:0])] == f_word);
      if (pop && f_pos == '0) assert (m_axis_tdata == f_word);
    end
  end
  always_comb if (f_past && !rst) begin
    cover (count_q == (PTR_W+1)'(DEPTH) && pop);
    cover (push && pop && count_q == (PTR_W+1)'(DEPTH - 1));
    cover (f_track && pop && f_pos == (PTR_W+1)'(0) && f_out == 8'(DEPTH + 2));
  end
  axis_checker #(.PAYLOAD_W(WIDTH), .ASSUME(1'b1)) f_chk_s_axis (
    .clk, .rst, .tvalid(s_axis_tvalid), .tready(s_axis_tready), .payload(s_axis_tdata));
  axis_checker #(.PAYLOAD_W(WIDTH)) f_chk_m_axis (
    .clk, .rst, .tvalid(m_axis_tvalid), .tready(m_axis_tready), .payload(m_axis_tdata));
`endif

endmodule

`default_nettype wire
