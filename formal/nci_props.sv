// SPDX-License-Identifier: Apache-2.0
// Formal harness of nci (formal/nci.sby): instantiates the block with small parameters and
// states its port contract; the handshake rules of both ports come from the block's own
// axis_checker instances (s_axis assumed, m_axis asserted) and the output FIFO's credit
// invariants from buf_out_fifo's FORMAL block.
//   - cells leave in (r, d) order: TUSER counts 0, 1, 2, ... and wraps; TLAST on d = last;
//   - no cell created or lost: cells out <= last-TX words in <= cells out + 8 (the credit
//     FIFO's depth: stored + in the pipeline);
//   - status_framing_error is exactly "some input beat had TLAST != (d == N_DOPPLER-1)",
//     frame_count exactly the completed input frames (counted here from the input beats);
//   - the power of a cell is the sum of |x|^2 over its NUM_TX words (NUM_RX = 1 here).
`default_nettype none

module nci_props (
  input wire logic       clk,
  input wire logic       rst,
  input wire logic [3:0] s_axis_tdata,
  input wire logic       s_axis_tvalid,
  input wire logic       s_axis_tlast,
  input wire logic       m_axis_tready
);
  localparam int NUM_TX = 2, NUM_RX = 1, N_RANGE = 2, N_DOPPLER = 2, DATA_W = 2;
  localparam int POW_W = 2 * DATA_W + 1, OUT_W = 8;

  logic             s_axis_tready, m_axis_tvalid, m_axis_tlast, framing;
  logic [OUT_W-1:0] m_axis_tdata;
  logic [1:0]       m_axis_tuser;
  logic [31:0]      frame_count;

  nci #(.NUM_TX(NUM_TX), .NUM_RX(NUM_RX), .N_RANGE(N_RANGE), .N_DOPPLER(N_DOPPLER),
        .DATA_W(DATA_W)) dut (
    .clk, .rst, .s_axis_tdata, .s_axis_tvalid, .s_axis_tready, .s_axis_tlast,
    .m_axis_tdata, .m_axis_tvalid, .m_axis_tready, .m_axis_tlast, .m_axis_tuser,
    .status_framing_error(framing), .frame_count);

  initial assume (rst);

  wire in_beat  = s_axis_tvalid && s_axis_tready;
  wire out_beat = m_axis_tvalid && m_axis_tready;

  // the input position as the environment sees it: (r, t, d)
  logic       f_past = 1'b0;
  logic       d_q, t_q, r_q;
  logic [1:0] cell_q;          // next expected TUSER
  logic [7:0] f_cells_in, f_cells_out;
  logic [7:0] f_frames;
  logic       f_err;
  logic [POW_W-1:0] f_part [N_DOPPLER];  // TX-0 power per Doppler bin of the current row
  logic [POW_W-1:0] f_exp  [8];          // expected powers in flight (cell index mod 8)

  function automatic logic [POW_W-1:0] pow1(input logic [3:0] w);
    logic signed [1:0] i, q;
    i = w[1:0];
    q = w[3:2];
    pow1 = POW_W'(unsigned'(4'(i * i))) + POW_W'(unsigned'(4'(q * q)));
  endfunction

  always_ff @(posedge clk) begin
    f_past <= 1'b1;
    if (rst) begin
      {d_q, t_q, r_q} <= '0;
      cell_q      <= '0;
      f_cells_in  <= '0;
      f_cells_out <= '0;
      f_frames    <= '0;
      f_err       <= 1'b0;
    end else begin
      if (in_beat) begin
        if (s_axis_tlast != d_q) f_err <= 1'b1;
        if (t_q == 1'b0) f_part[d_q] <= pow1(s_axis_tdata);
        else begin
          f_exp[f_cells_in[2:0]] <= f_part[d_q] + pow1(s_axis_tdata);
          f_cells_in <= f_cells_in + 8'd1;
        end
        d_q <= !d_q;
        if (d_q) begin
          t_q <= !t_q;
          if (t_q) begin
            r_q <= !r_q;
            if (r_q) f_frames <= f_frames + 8'd1;
          end
        end
      end
      if (out_beat) begin
        cell_q      <= cell_q + 2'd1;
        f_cells_out <= f_cells_out + 8'd1;
      end
    end
  end

  always_comb if (f_past && !rst) begin
    assert (8'(f_cells_in - f_cells_out) <= 8'd8);
    if (m_axis_tvalid) begin
      assert (f_cells_in != f_cells_out);
      assert (m_axis_tuser == cell_q);
      assert (m_axis_tlast == cell_q[0]);
      assert (m_axis_tdata == OUT_W'(f_exp[f_cells_out[2:0]]));
    end
    assert (framing == f_err);
    assert (frame_count[7:0] == f_frames);
  end
  always_comb if (f_past && !rst) begin
    cover (out_beat && cell_q == 2'd3 && m_axis_tdata != '0);
    cover (framing && m_axis_tvalid && !m_axis_tready);
    cover (frame_count == 32'd1 && !m_axis_tvalid);
  end
endmodule

`default_nettype wire
