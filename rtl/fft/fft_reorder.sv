// SPDX-License-Identifier: Apache-2.0
// Bit-reverse to natural order buffer of the streaming FFT: two banks of N words written at
// the bit-reversed sample index and read in natural order onto an AXI4-Stream style output
// register. A bank slot may be rewritten as soon as it has been read, so continuous frames
// pass without a gap. wr_ok comes from registers only: the slot compare of the write position
// it concerns (`wr_addr < rd_ptr_q`) is computed a cycle ahead from wr_step / wr_pos_nxt, so
// the caller's advance enable does not wait for a comparator; wr_ok_nxt is the same flag for
// the next cycle (from this cycle's write, step and read), for a caller whose advance enable
// is itself a register decided a cycle ahead (fft_axis).
`default_nettype none

module fft_reorder #(
  // Transform length, power of two, 16..4096.
  parameter int N = 64,
  // Word width (all lanes plus the overflow flag), >= 1.
  parameter int WIDTH = 33,
  // Bins read out per frame, 1..N: bins 0..N_OUT-1 (TLAST on N_OUT-1); the rest are never
  // read (their bank is released with bin N_OUT-1).
  parameter int N_OUT = N
) (
  input  logic clk,
  input  logic rst,
  // Write side: wr_en only when wr_ok; wr_pos is the pipeline (bit-reversed) index, a
  // register of the caller that takes wr_pos_nxt on the cycles wr_step is set and holds
  // otherwise (any value out of reset).
  input  logic                    wr_en,
  input  logic [$clog2(N)-1:0]    wr_pos,
  input  logic                    wr_step,
  input  logic [$clog2(N)-1:0]    wr_pos_nxt,
  input  logic [WIDTH-1:0]        wr_data,
  output logic                    wr_ok,
  // wr_ok of the next cycle: from this cycle's registers, wr_en, wr_step / wr_pos_nxt and the
  // output handshake (ignore it in a reset cycle).
  output logic                    wr_ok_nxt,
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
  if (N_OUT < 1 || N_OUT > N) begin : g_bad_n_out
    $fatal(1, "%m: N_OUT=%0d not in 1..N (%0d)", N_OUT, N);
  end

  logic [WIDTH-1:0] mem_q [2*N];
  logic [1:0]       full_q, full_d;      // bank holds a complete frame not yet fully read
  logic             wb_q, rb_q;          // bank being written / read
  logic [LOG2N-1:0] rd_ptr_q;            // next natural-order address to read
  logic [LOG2N-1:0] wr_addr, nxt_addr;
  logic             pop, rd_last, wr_last;
  logic             lt_q, lt_d;              // wr_addr < rd_ptr_q, from registers
  logic             wb_d, rb_d;
  logic [WIDTH-1:0] m_data_q;
  logic [LOG2N-1:0] m_user_q;
  logic             m_last_q, m_valid_q;

  always_comb begin
    wr_addr  = '0;
    nxt_addr = '0;
    for (int b = 0; b < LOG2N; b++) begin
      wr_addr[b]  = wr_pos[LOG2N-1-b];
      nxt_addr[b] = wr_pos_nxt[LOG2N-1-b];
    end
  end

  // Free bank, or the slot of the bank under read has already been read.
  assign wr_ok   = !full_q[wb_q] || (rb_q == wb_q && lt_q);
  assign pop     = full_q[rb_q] && (!m_valid_q || m_axis_tready);
  assign rd_last = rd_ptr_q == LOG2N'(N_OUT - 1);
  assign wr_last = wr_pos == LOG2N'(N - 1);

  // Next cycle's wr_addr < rd_ptr_q: the four compares (write position held or stepped x
  // read pointer held or advanced) from registers, then selected by wr_step and pop. An
  // advanced pointer is rd_ptr_q + 1 (a < p + 1 is a <= p), or 0 after the bank's last word.
  always_comb begin
    logic lt_hold, lt_step;
    lt_hold = pop ? (!rd_last && wr_addr <= rd_ptr_q) : wr_addr < rd_ptr_q;
    lt_step = pop ? (!rd_last && nxt_addr <= rd_ptr_q) : nxt_addr < rd_ptr_q;
    lt_d    = wr_step ? lt_step : lt_hold;
  end

  always_comb begin
    full_d = full_q;
    if (pop && rd_last) full_d[rb_q] = 1'b0;
    if (wr_en && wr_last) full_d[wb_q] = 1'b1;
  end
  assign wb_d      = wb_q ^ (wr_en && wr_last);
  assign rb_d      = rb_q ^ (pop && rd_last);
  assign wr_ok_nxt = !full_d[wb_d] || (rb_d == wb_d && lt_d);

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
      lt_q     <= 1'b0;                    // nothing is below rd_ptr_q = 0
      m_valid_q <= 1'b0;
    end else begin
      full_q <= full_d;
      lt_q   <= lt_d;
      wb_q   <= wb_d;
      rb_q   <= rb_d;
      if (pop) begin
        rd_ptr_q <= rd_last ? '0 : rd_ptr_q + 1'b1;
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

  // AXI4-Stream protocol on the output port (rtl/common/axis_checker.sv)
  axis_checker #(.PAYLOAD_W(WIDTH + 1 + LOG2N)) u_chk_m_axis (
    .clk, .rst, .tvalid(m_axis_tvalid), .tready(m_axis_tready),
    .payload({m_axis_tuser, m_axis_tlast, m_axis_tdata}));

`ifdef FORMAL
  // Formal properties (formal/fft_reorder.sby). Bank reuse: a slot is written only when it
  // holds no unread sample (f_pend: written, not yet read) and read only when it holds one;
  // the reader takes the banks in the order they were filled; TLAST/TUSER positions; the
  // look-ahead compare lt_q equals the compare of the current write position.
  logic         f_past = 1'b0;
  logic         f_stepped = 1'b0;          // the previous cycle was out of reset
  logic [LOG2N-1:0] f_pos_nxt = '0;       // wr_pos this cycle by the wr_step contract
  logic         f_ok_nxt = 1'b0;           // last cycle's wr_ok_nxt
  logic [2*N-1:0] f_pend = '0;
  logic [LOG2N-1:0] f_wpos = '0;   // write positions arrive in pipeline order 0..N-1
  logic             f_written, f_unread;
  function automatic logic [LOG2N-1:0] f_bitrev(input logic [LOG2N-1:0] x);
    for (int b = 0; b < LOG2N; b++) f_bitrev[b] = x[LOG2N-1-b];
  endfunction
  always_ff @(posedge clk) begin
    f_past    <= 1'b1;
    f_stepped <= !rst;
    f_pos_nxt <= wr_step ? wr_pos_nxt : wr_pos;
    f_ok_nxt  <= wr_ok_nxt;
    if (rst) begin
      f_pend <= '0;
      f_wpos <= '0;
    end else begin
      if (pop) f_pend[{rb_q, rd_ptr_q}] <= 1'b0;
      if (wr_en) begin
        f_pend[{wb_q, wr_addr}] <= 1'b1;
        f_wpos <= f_wpos + 1'b1;
      end
    end
  end
`ifdef F_TOP_FFT_REORDER
  initial assume (rst);
  always_comb if (!rst) begin
    assume (!wr_en || wr_ok);
    assume (wr_pos == f_wpos);
    if (f_stepped) assume (wr_pos == f_pos_nxt);
  end
`endif
  always_comb begin
    f_written = 1'b0;
    f_unread  = 1'b0;
    if (f_past && !rst) begin
    if (wr_en) assert (!f_pend[{wb_q, wr_addr}] || (pop && {rb_q, rd_ptr_q} == {wb_q, wr_addr}));
    if (pop) assert (f_pend[{rb_q, rd_ptr_q}]);
    assert (lt_q == (wr_addr < rd_ptr_q));
    if (f_stepped) assert (wr_ok == f_ok_nxt);
    // bank order invariants
    if (wb_q != rb_q) assert (!full_q[wb_q]);
    if (wb_q == rb_q) assert (full_q[0] == full_q[1]);
    if (!full_q[rb_q]) assert (!full_q[!rb_q] && rd_ptr_q == '0 && wb_q == rb_q);
    if (m_axis_tvalid) assert (m_axis_tlast == (m_axis_tuser == LOG2N'(N_OUT - 1)));
    // inductive form of the bank reuse rule: which slots hold unread samples
    for (int b = 0; b < 2; b++) begin
      for (int i = 0; i < N; i++) begin
        f_written = (b == int'(wb_q)) && (f_bitrev(LOG2N'(i)) < f_wpos);
        f_unread  = full_q[b] && !(b == int'(rb_q) && LOG2N'(i) < rd_ptr_q);
        assert (f_pend[b*N + i] == (f_written || f_unread));
        if (f_written && full_q[b]) assert (b == int'(rb_q) && LOG2N'(i) < rd_ptr_q);
      end
    end
  end
  end
  always_comb if (f_past && !rst) begin
    cover (full_q == 2'b11);
    cover (m_axis_tvalid && m_axis_tlast && !m_axis_tready);
    cover (wr_en && full_q[wb_q]);   // a slot of the bank under read is reused
  end
`endif
endmodule

`default_nettype wire
