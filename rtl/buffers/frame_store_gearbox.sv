// SPDX-License-Identifier: Apache-2.0
// Width converter between two power-of-two widths with AXI4-Stream handshakes: packs either
// N narrow beats into one wide beat (first beat in the least significant
// bits, the little-endian byte order of AXI4 and of the DMA words) or one wide beat into N
// narrow beats (least significant part first). Equal widths pass straight through.
`default_nettype none

module frame_store_gearbox #(
  // Input width in bits, power of two, 8..4096.
  parameter int IN_W = 128,
  // Output width in bits, power of two, 8..4096.
  parameter int OUT_W = 128
) (
  input  wire logic             clk,
  input  wire logic             rst,
  // Sink
  input  wire logic [IN_W-1:0]  s_axis_tdata,
  input  wire logic             s_axis_tvalid,
  output logic                  s_axis_tready,
  // Source
  output logic      [OUT_W-1:0] m_axis_tdata,
  output logic                  m_axis_tvalid,
  input  wire logic             m_axis_tready
);

  // Parameter checks: stop elaboration on illegal values.
  if (IN_W < 8 || IN_W > 4096 || (IN_W & (IN_W - 1)) != 0) begin : g_bad_in_w
    $fatal(1, "frame_store_gearbox (%m): IN_W=%0d must be a power of two in 8..4096", IN_W);
  end
  if (OUT_W < 8 || OUT_W > 4096 || (OUT_W & (OUT_W - 1)) != 0) begin : g_bad_out_w
    $fatal(1, "frame_store_gearbox (%m): OUT_W=%0d must be a power of two in 8..4096", OUT_W);
  end

  if (IN_W == OUT_W) begin : g_pass
    assign m_axis_tdata  = s_axis_tdata;
    assign m_axis_tvalid = s_axis_tvalid;
    assign s_axis_tready = m_axis_tready;
    // clk/rst unused in the pass-through case
    /* verilator lint_off UNUSEDSIGNAL */
    logic unused_ok;
    assign unused_ok = clk ^ rst;
    /* verilator lint_on UNUSEDSIGNAL */

  end else if (IN_W < OUT_W) begin : g_pack
    // N narrow beats -> one wide beat, held in a register until taken
    localparam int N   = OUT_W / IN_W;
    localparam int N_W = $clog2(N);
    logic [OUT_W-1:0] acc_q;
    logic [N_W-1:0]   idx_q;
    logic             full_q;
    logic             in_beat;

    // accepts while the full word leaves: one wide beat every N clocks
    assign s_axis_tready = !rst && (!full_q || m_axis_tready);
    assign in_beat       = s_axis_tvalid && s_axis_tready;
    assign m_axis_tvalid = full_q;
    assign m_axis_tdata  = acc_q;

    always_ff @(posedge clk) begin
      if (in_beat) acc_q[idx_q*IN_W +: IN_W] <= s_axis_tdata;
    end

    always_ff @(posedge clk) begin
      if (rst) begin
        idx_q  <= '0;
        full_q <= 1'b0;
      end else begin
        if (m_axis_tvalid && m_axis_tready) full_q <= 1'b0;
        if (in_beat) begin
          idx_q <= idx_q + 1'b1;
          if (idx_q == N_W'(N - 1)) full_q <= 1'b1;
        end
      end
    end

  end else begin : g_split
    // one wide beat -> N narrow beats, least significant first
    localparam int N   = IN_W / OUT_W;
    localparam int N_W = $clog2(N);
    logic [IN_W-1:0] hold_q;
    logic [N_W-1:0]  idx_q;
    logic            full_q;
    logic            out_beat;

    // reloads while the last part leaves: N narrow beats every N clocks
    assign out_beat      = m_axis_tvalid && m_axis_tready;
    assign s_axis_tready = !rst && (!full_q || (out_beat && idx_q == N_W'(N - 1)));
    assign m_axis_tvalid = full_q;
    assign m_axis_tdata  = hold_q[idx_q*OUT_W +: OUT_W];

    always_ff @(posedge clk) begin
      if (s_axis_tvalid && s_axis_tready) hold_q <= s_axis_tdata;
    end

    always_ff @(posedge clk) begin
      if (rst) begin
        idx_q  <= '0;
        full_q <= 1'b0;
      end else begin
        if (out_beat) begin
          idx_q <= idx_q + 1'b1;
          if (idx_q == N_W'(N - 1)) full_q <= 1'b0;
        end
        if (s_axis_tvalid && s_axis_tready) full_q <= 1'b1;
      end
    end
  end

endmodule

`default_nettype wire
