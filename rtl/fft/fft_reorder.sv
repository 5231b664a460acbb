// SPDX-License-Identifier: Apache-2.0
// Bit-reverse to natural order buffer of the streaming FFT: two banks of N words written at
// the bit-reversed sample index and read in natural order onto an AXI4-Stream style output
// register. A bank slot may be rewritten as soon as it has been read, so continuous frames
// pass without a gap.
`default_nettype none

module fft_reorder #(
  // Transform length, power of two, 16..4096.
  parameter int N = 64,
  // Word width (all lanes plus the overflow flag), >= 1.
  parameter int WIDTH = 33
) (
  input  logic clk,
  input  logic rst,
  // Write side: wr_en only when wr_ok; wr_pos is the pipeline (bit-reversed) index.
  input  logic                    wr_en,
  input  logic [$clog2(N)-1:0]    wr_pos,
  input  logic [WIDTH-1:0]        wr_data,
  output logic                    wr_ok,
  // Read side (natural order, registered outputs).
  output logic [WIDTH-1:0]        m_axis_tdata,
  output logic                    m_axis_tvalid,
  input  logic                    m_axis_tready,
  output logic                    m_axis_tlast,
  output logic [$clog2(N)-1:0]    m_axis_tuser
);
  localparam int LOG2N = $clog2(N);

  if (N < 2 || (1 << LOG2N) != N) begin : g_bad_n
    $fatal(1, "%m: N=%0d must be a power of two", N);
  end

  logic [WIDTH-1:0] mem_q [2*N];
  logic [1:0]       full_q, full_d;      // bank holds a complete frame not yet fully read
  logic             wb_q, rb_q;          // bank being written / read
  logic [LOG2N-1:0] rd_ptr_q;            // next natural-order address to read
  logic [LOG2N-1:0] wr_addr;
  logic             pop, rd_last, wr_last;
  logic [WIDTH-1:0] m_data_q;
  logic [LOG2N-1:0] m_user_q;
  logic             m_last_q, m_valid_q;

  always_comb begin
    wr_addr = '0;
    for (int b = 0; b < LOG2N; b++) wr_addr[b] = wr_pos[LOG2N-1-b];
  end

  // Free bank, or the slot of the bank under read has already been read.
  assign wr_ok   = !full_q[wb_q] || (rb_q == wb_q && wr_addr < rd_ptr_q);
  assign pop     = full_q[rb_q] && (!m_valid_q || m_axis_tready);
  assign rd_last = rd_ptr_q == LOG2N'(N - 1);
  assign wr_last = wr_pos == LOG2N'(N - 1);

  always_comb begin
    full_d = full_q;
    if (pop && rd_last) full_d[rb_q] = 1'b0;
    if (wr_en && wr_last) full_d[wb_q] = 1'b1;
  end

  always_ff @(posedge clk) begin
    if (wr_en) mem_q[{wb_q, wr_addr}] <= wr_data;
    if (pop) begin
      m_data_q <= mem_q[{rb_q, rd_ptr_q}];
      m_user_q <= rd_ptr_q;
      m_last_q <= rd_last;
    end
  end

  always_ff @(posedge clk) begin
    if (rst) begin
      full_q   <= '0;
      wb_q     <= 1'b0;
      rb_q     <= 1'b0;
      rd_ptr_q <= '0;
      m_valid_q <= 1'b0;
    end else begin
      full_q <= full_d;
      if (wr_en && wr_last) wb_q <= ~wb_q;
      if (pop) begin
        rd_ptr_q <= rd_last ? '0 : rd_ptr_q + 1'b1;
        if (rd_last) rb_q <= ~rb_q;
        m_valid_q <= 1'b1;
      end else if (m_axis_tready) begin
        m_valid_q <= 1'b0;
      end
    end
  end

  assign m_axis_tdata  = m_data_q;
  assign m_axis_tuser  = m_user_q;
  assign m_axis_tlast  = m_last_q;
  assign m_axis_tvalid = m_valid_q;
endmodule

`default_nettype wire
