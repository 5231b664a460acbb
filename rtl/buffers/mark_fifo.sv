// SPDX-License-Identifier: Apache-2.0
// Small first-in first-out queue of per-frame marks (e.g. "this frame was damaged"), held in
// flip-flops as a shift register: the head is always bit-slice 0, so it is readable in the
// same clock as `empty` falls. radar_pipeline queues frame_align's damage mark of every frame
// here until the Doppler FFT emits the last word of that frame.
//
// push: store push_data (dropped, and `overflow` set, when full and not popping);
// pop:  drop the head (ignored, and `underflow` set, when empty); push and pop together on a
//       non-empty queue do both. Both flags are sticky until reset: nothing is lost silently.
`default_nettype none

module mark_fifo #(
  parameter int DEPTH = 4,  // marks held, 2..64
  parameter int WIDTH = 1   // bits per mark, 1..64
) (
  input  wire logic               clk,
  input  wire logic               rst,
  input  wire logic               push,
  input  wire logic [WIDTH-1:0]   push_data,
  input  wire logic               pop,
  output logic      [WIDTH-1:0]   head,       // oldest mark (0 when empty)
  output logic                    empty,
  output logic                    full,
  output logic [$clog2(DEPTH):0]  count,
  output logic                    overflow,   // sticky: a push found the queue full
  output logic                    underflow   // sticky: a pop found the queue empty
);

  if (DEPTH < 2 || DEPTH > 64) begin : g_bad_depth
    $fatal(1, "%m: DEPTH=%0d must be in 2..64", DEPTH);
  end
  if (WIDTH < 1 || WIDTH > 64) begin : g_bad_width
    $fatal(1, "%m: WIDTH=%0d must be in 1..64", WIDTH);
  end

  localparam int CW = $clog2(DEPTH) + 1;

  logic [WIDTH-1:0] q [DEPTH];
  logic [CW-1:0]    cnt_q;
  logic             ovf_q, unf_q;
  logic             do_pop, do_push;
  logic [CW-2:0]    wr_idx;         // < DEPTH whenever do_push

  assign empty   = (cnt_q == '0);
  assign full    = (cnt_q == CW'(DEPTH));
  assign do_pop  = pop && !empty;
  assign do_push = push && (!full || do_pop);
  assign wr_idx  = (CW-1)'(do_pop ? cnt_q - 1'b1 : cnt_q);

  always_ff @(posedge clk) begin
    if (rst) begin
      cnt_q <= '0;
      ovf_q <= 1'b0;
      unf_q <= 1'b0;
      for (int i = 0; i < DEPTH; i++) q[i] <= '0;
    end else begin
      if (push && !do_push) ovf_q <= 1'b1;
      if (pop && empty) unf_q <= 1'b1;
      if (do_pop) begin
        for (int i = 0; i < DEPTH - 1; i++) q[i] <= q[i+1];
        q[DEPTH-1] <= '0;
      end
      if (do_push) q[wr_idx] <= push_data;
      cnt_q <= cnt_q + CW'(do_push) - CW'(do_pop);
    end
  end

  assign head      = empty ? '0 : q[0];
  assign count     = cnt_q;
  assign overflow  = ovf_q;
  assign underflow = unf_q;

`ifdef FORMAL
  // Formal properties (formal/mark_fifo.sby). Occupancy: count == accepted pushes - accepted
  // pops (modulo the counter width), never above DEPTH; slots past the count hold 0; head
  // order; overflow/underflow sticky and set exactly on a refused push/pop.
  logic          f_past = 1'b0;
  logic [CW-1:0] f_pushes = '0, f_pops = '0;
  initial assume (rst);
  always_ff @(posedge clk) begin
    f_past <= 1'b1;
    if (rst) begin
      f_pushes <= '0;
      f_pops   <= '0;
    end else begin
      f_pushes <= f_pushes + CW'(do_push);
      f_pops   <= f_pops + CW'(do_pop);
    end
  end
  always_comb if (f_past && !rst) begin
    assert (cnt_q <= CW'(DEPTH));
    assert (cnt_q == CW'(f_pushes - f_pops));
    for (int i = 0; i < DEPTH; i++) if (CW'(i) >= cnt_q) assert (q[i] == '0);
  end
  always_ff @(posedge clk) if (f_past && $past(rst)) begin
    assert (cnt_q == '0 && !ovf_q && !unf_q);  // reset clears the queue and both flags
  end
  always_ff @(posedge clk) if (f_past && !$past(rst) && !rst) begin
    // sticky flags, and set only by a refused operation
    if ($past(ovf_q)) assert (ovf_q);
    if ($past(unf_q)) assert (unf_q);
    assert (ovf_q == ($past(ovf_q) || $past(push && full && !pop)));
    assert (unf_q == ($past(unf_q) || $past(pop && empty)));
    // a push into an empty queue (or one holding a single popped mark) is the next head
    if ($past(push && (cnt_q == '0 || (cnt_q == CW'(1) && pop))))
      assert (head == $past(push_data));
    // a pop exposes the second-oldest mark
    if ($past(pop && cnt_q >= CW'(2))) assert (head == $past(q[1]));
  end
  always_comb if (f_past && !rst) begin
    cover (full);
    cover (ovf_q && unf_q && cnt_q == CW'(1));
  end
`endif

endmodule

`default_nettype wire
