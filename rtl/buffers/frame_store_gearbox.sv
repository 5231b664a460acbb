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

`ifdef FORMAL
  // Formal properties (formal/frame_store_gearbox.sby, tasks per direction). Both ports obey
  // AXI-Stream (sink assumed, source asserted: rtl/common/axis_checker.sv); no beat created
  // or lost: narrow beats == N x wide beats + the parts held; contents: any narrow part
  // (picked by the solver) sits in the right slice of the right wide word.
  localparam int F_N  = IN_W < OUT_W ? OUT_W / IN_W : IN_W / OUT_W;
  localparam int F_NW = F_N > 1 ? $clog2(F_N) : 1;
  localparam int F_PW = IN_W < OUT_W ? IN_W : OUT_W;
  logic f_past = 1'b0;
  logic [7:0] f_in = '0, f_out = '0;
  wire f_ib = s_axis_tvalid && s_axis_tready;
  wire f_ob = m_axis_tvalid && m_axis_tready;
  always_ff @(posedge clk) begin
    f_past <= 1'b1;
    if (rst) begin
      f_in  <= '0;
      f_out <= '0;
    end else begin
      f_in  <= f_in + 8'(f_ib);
      f_out <= f_out + 8'(f_ob);
    end
  end
`ifdef F_TOP_FRAME_STORE_GEARBOX
  initial assume (rst);
`endif
  (* anyconst *) logic [F_NW-1:0] f_slot;   // which part of a wide word is watched
  (* anyseq *) logic f_pick;                // the solver picks the watched word
  logic [F_PW-1:0] f_part;
  logic f_track = 1'b0;
  axis_checker #(.PAYLOAD_W(IN_W), .ASSUME(1'b1)) f_chk_s_axis (
    .clk, .rst, .tvalid(s_axis_tvalid), .tready(s_axis_tready), .payload(s_axis_tdata));
  axis_checker #(.PAYLOAD_W(OUT_W)) f_chk_m_axis (
    .clk, .rst, .tvalid(m_axis_tvalid), .tready(m_axis_tready), .payload(m_axis_tdata));
`endif

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

`ifdef FORMAL
    // watch narrow input beat number f_slot of some wide word: it leaves in slice f_slot
    always_ff @(posedge clk) begin
      if (rst) f_track <= 1'b0;
      else begin
        if (f_track && f_ob) f_track <= 1'b0;
        if (!f_track && f_ib && f_pick && idx_q == f_slot) begin
          f_track <= 1'b1;
          f_part  <= s_axis_tdata;
        end
      end
    end
    always_comb if (f_past && !rst) begin
      assert (f_in == 8'(F_N) * f_out + 8'(idx_q) + (full_q ? 8'(F_N) : 8'd0));
      if (full_q) assert (idx_q == '0);
      if (f_track) begin
        assert (acc_q[f_slot*IN_W +: IN_W] == f_part);
        assert (full_q || idx_q > f_slot);
        if (f_ob) assert (m_axis_tdata[f_slot*IN_W +: IN_W] == f_part);
      end
    end
    always_comb if (f_past && !rst) begin
      cover (f_track && f_ob && f_slot == F_NW'(F_N - 1) && f_out == 8'd2);
      cover (f_ob && f_ib);
    end
`endif

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
`ifdef FORMAL
    // watch slice f_slot of some wide input word: it leaves as narrow beat number f_slot
    always_ff @(posedge clk) begin
      if (rst) f_track <= 1'b0;
      else begin
        if (f_track && out_beat && idx_q == f_slot) f_track <= 1'b0;
        if (!f_track && f_ib && f_pick) begin
          f_track <= 1'b1;
          f_part  <= s_axis_tdata[f_slot*OUT_W +: OUT_W];
        end
      end
    end
    always_comb if (f_past && !rst) begin
      assert (8'(F_N) * f_in == f_out + (full_q ? 8'(F_N) - 8'(idx_q) : 8'd0));
      if (!full_q) assert (idx_q == '0);
      if (f_track) begin
        assert (full_q && idx_q <= f_slot);
        assert (hold_q[f_slot*OUT_W +: OUT_W] == f_part);
        if (out_beat && idx_q == f_slot) assert (m_axis_tdata == f_part);
      end
    end
    always_comb if (f_past && !rst) begin
      cover (f_track && out_beat && idx_q == f_slot && f_slot == F_NW'(F_N - 1)
             && f_in == 8'd2);
      cover (out_beat && f_ib);
    end
`endif
  end

endmodule

`default_nettype wire
