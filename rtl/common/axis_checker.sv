// SPDX-License-Identifier: Apache-2.0
// AXI4-Stream protocol checker: the one place the handshake rules of every streaming port
// are written down. Instantiate one per port, beside the port, with the port's signals:
//
//   axis_checker #(.PAYLOAD_W(DATA_W + 1)) u_chk_m_axis (
//     .clk, .rst, .tvalid(m_axis_tvalid), .tready(m_axis_tready),
//     .payload({m_axis_tlast, m_axis_tdata}));
//
// Rules (AMBA AXI4-Stream, IHI 0051A section 2.2.1), checked on every rising edge out of reset:
//   1. TVALID, once high, stays high until the beat with TREADY (no withdrawn beat);
//   2. the payload (TDATA, TLAST, TUSER, ... concatenated into `payload`) is stable while
//      TVALID && !TREADY;
//   3. TVALID is never X/Z once reset has been seen (simulation only).
// Reset is handled here once: a stall registered at an edge with rst high, or a check at an
// edge with rst high, is ignored (the rules do not hold across a reset).
//
// Simulation (`SYNTHESIS` not defined): immediate assertions whose message names the instance
// (%m), so the failing port is named. Synthesis (`SYNTHESIS` defined, as Vivado and the
// Yosys estimate do): the module is empty. Formal (`FORMAL` defined, e.g. SymbiYosys
// `read -formal`): rules 1 and 2 become `assume` when ASSUME = 1 (a port driven by the
// environment) and `assert` otherwise (a port the design drives).
`default_nettype none

module axis_checker #(
  parameter int PAYLOAD_W = 1,   // width of {TUSER, TLAST, TDATA, ...} as concatenated
  parameter bit ASSUME    = 1'b0 // formal only: 1 = assume the rules (input port)
) (
  input  wire logic                 clk,
  input  wire logic                 rst,     // synchronous, active high
  input  wire logic                 tvalid,
  input  wire logic                 tready,
  input  wire logic [PAYLOAD_W-1:0] payload
);

  if (PAYLOAD_W < 1) begin : g_bad_payload_w
    $fatal(1, "%m: PAYLOAD_W=%0d must be >= 1", PAYLOAD_W);
  end

`ifdef FORMAL
  logic                 stall_q = 1'b0;
  logic [PAYLOAD_W-1:0] held_q;
  always_ff @(posedge clk) begin
    stall_q <= !rst && tvalid && !tready;
    held_q  <= payload;
  end
  if (ASSUME) begin : g_assume
    always_comb if (!rst && stall_q) begin
      assume (tvalid);
      assume (payload == held_q);
    end
  end else begin : g_assert
    always_comb if (!rst && stall_q) begin
      assert (tvalid);
      assert (payload == held_q);
    end
  end
`elsif SYNTHESIS
  // nothing: the checker is invisible to synthesis
`else
  // initial values: no check before the first edge (random initial state in Verilator)
  /* verilator lint_off PROCASSINIT */
  logic                 stall_q = 1'b0;     // previous edge: out of reset and stalled
  logic                 seen_rst_q = 1'b0;  // reset has been applied once
  /* verilator lint_on PROCASSINIT */
  logic [PAYLOAD_W-1:0] held_q;
  always_ff @(posedge clk) begin
    stall_q    <= !rst && tvalid && !tready;
    seen_rst_q <= seen_rst_q || rst;
    held_q     <= payload;
    if (!rst && stall_q) begin
      assert (tvalid) else $error("%m: AXI-Stream TVALID dropped while stalled");
      assert (payload == held_q)
        else $error("%m: AXI-Stream payload (TDATA/TLAST/TUSER) changed while stalled");
    end
    if (!rst && seen_rst_q) begin
      assert (!$isunknown(tvalid)) else $error("%m: AXI-Stream TVALID is X after reset");
    end
  end
  wire unused_assume = ASSUME;
`endif

endmodule

`default_nettype wire
