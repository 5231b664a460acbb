// SPDX-License-Identifier: Apache-2.0
// Control and status plane of the radar processor (docs/regs.md): the AXI4-Lite register
// block generated from rtl/regs/radar_regs.rdl (radar_regs) plus what the generator cannot
// express:
//   - the settings (SETTINGS, CFAR_SCALE, PACKET are external registers of radar_regs, held
//     here): each write is checked whole, after its byte strobes are merged with the old
//     value; a write holding an out-of-range field (a reserved CFAR kind, max_detections 0 or
//     above MAX_DETECTIONS, packet words 0 or above PACKET_WORDS) is refused whole (the
//     register keeps its value), counted in CFG_ERRORS and sets STATUS.cfg_error;
//   - the shadow rule: the pending set (always legal) is copied whole to the active set, the
//     cfg_* outputs, in the cycle after a frame_start pulse and at no other time (a write
//     accepted in that same cycle waits for the next frame start);
//   - the event pulses (frame_done, packet_done, drop, error) feed the saturating counters
//     FRAMES, PACKETS, DROPS, ERRORS and the sticky write-one-to-clear STATUS flags (an event
//     in the cycle of the clearing write keeps its flag);
//   - irq: registered, high while any STATUS flag whose IRQ_ENABLE bit is set is high.
// Bit-accurate model: model/radar_ctrl.py. Everything is cleared by `rst` only.
`default_nettype none

module radar_ctrl #(
  parameter int          MAX_DETECTIONS  = 256,   // bound of SETTINGS.max_detections, reset value
  parameter int          PACKET_WORDS    = 1024,  // bound of PACKET.words, reset value
  parameter int          CFAR_KIND       = 0,     // reset CFAR kind: 0 = CA, 1 = OS
  parameter int unsigned CFAR_SCALE      = 0,     // reset threshold scale
  parameter bit          CLUTTER_REMOVAL = 1'b0,  // reset static-clutter removal switch
  localparam int         ADDR_W          = radar_regs_pkg::RADAR_REGS_MIN_ADDR_WIDTH
) (
  input  wire logic              clk,
  input  wire logic              rst,
  // AXI4-Lite slave (32-bit data, byte addresses)
  input  wire logic              s_axil_awvalid,
  output logic                   s_axil_awready,
  input  wire logic [ADDR_W-1:0] s_axil_awaddr,
  input  wire logic [2:0]        s_axil_awprot,
  input  wire logic              s_axil_wvalid,
  output logic                   s_axil_wready,
  input  wire logic [31:0]       s_axil_wdata,
  input  wire logic [3:0]        s_axil_wstrb,
  output logic                   s_axil_bvalid,
  input  wire logic              s_axil_bready,
  output logic [1:0]             s_axil_bresp,
  input  wire logic              s_axil_arvalid,
  output logic                   s_axil_arready,
  input  wire logic [ADDR_W-1:0] s_axil_araddr,
  input  wire logic [2:0]        s_axil_arprot,
  output logic                   s_axil_rvalid,
  input  wire logic              s_axil_rready,
  output logic [31:0]            s_axil_rdata,
  output logic [1:0]             s_axil_rresp,
  // event pulses from the datapath (one cycle each)
  input  wire logic              frame_start,   // the active settings change after this cycle
  input  wire logic              frame_done,
  input  wire logic              packet_done,
  input  wire logic              drop,
  input  wire logic              error,
  // active settings (change only in the cycle after frame_start)
  output logic [1:0]             cfg_cfar_kind,
  output logic                   cfg_clutter_removal,
  output logic [15:0]            cfg_max_detections,
  output logic [31:0]            cfg_cfar_scale,
  output logic [15:0]            cfg_packet_words,
  output logic                   irq
);

  // ---- parameter checks -----------------------------------------------------------------
  if (MAX_DETECTIONS < 1 || MAX_DETECTIONS > 65535) begin : g_bad_max_detections
    $fatal(1, "%m: MAX_DETECTIONS=%0d must be 1..65535 (a 16-bit register field)",
           MAX_DETECTIONS);
  end
  if (PACKET_WORDS < 1 || PACKET_WORDS > 65535) begin : g_bad_packet_words
    $fatal(1, "%m: PACKET_WORDS=%0d must be 1..65535 (a 16-bit register field)", PACKET_WORDS);
  end
  if (CFAR_KIND < 0 || CFAR_KIND > 1) begin : g_bad_cfar_kind
    $fatal(1, "%m: CFAR_KIND=%0d must be 0 (CA) or 1 (OS)", CFAR_KIND);
  end

  radar_regs_pkg::radar_regs__in_t  hwif_in;
  radar_regs_pkg::radar_regs__out_t hwif_out;

  radar_regs u_regs (
    .clk, .rst,
    .s_axil_awready, .s_axil_awvalid, .s_axil_awaddr, .s_axil_awprot,
    .s_axil_wready, .s_axil_wvalid, .s_axil_wdata, .s_axil_wstrb,
    .s_axil_bready, .s_axil_bvalid, .s_axil_bresp,
    .s_axil_arready, .s_axil_arvalid, .s_axil_araddr, .s_axil_arprot,
    .s_axil_rready, .s_axil_rvalid, .s_axil_rdata, .s_axil_rresp,
    .hwif_in, .hwif_out);

  // ---- settings: the pending set (checked on write) and the active set ------------------
  typedef struct packed {
    logic [1:0]  cfar_kind;
    logic        clutter_removal;
    logic [15:0] max_detections;
    logic [31:0] cfar_scale;
    logic [15:0] packet_words;
  } settings_t;
  localparam settings_t RESET_SET = {2'(CFAR_KIND), CLUTTER_REMOVAL, 16'(MAX_DETECTIONS),
                                     32'(CFAR_SCALE), 16'(PACKET_WORDS)};

  function automatic logic legal(input logic [1:0] kind, input logic [15:0] maxdet,
                                 input logic [15:0] words);
    legal = kind <= 2'd1 && maxdet != '0 && 32'(maxdet) <= 32'(MAX_DETECTIONS)
            && words != '0 && 32'(words) <= 32'(PACKET_WORDS);
  endfunction

  settings_t pend_q, active_q, cand;

  wire set_wr   = hwif_out.SETTINGS.req && hwif_out.SETTINGS.req_is_wr;
  wire scale_wr = hwif_out.CFAR_SCALE.req && hwif_out.CFAR_SCALE.req_is_wr;
  wire pkt_wr   = hwif_out.PACKET.req && hwif_out.PACKET.req_is_wr;

  // the pending set as this cycle's write would leave it (byte strobes merged with the old
  // value); the write is refused whole when the result is not legal
  always_comb begin
    cand = pend_q;
    if (set_wr) begin
      cand.cfar_kind = (pend_q.cfar_kind & ~hwif_out.SETTINGS.wr_biten.cfar_kind)
                     | (hwif_out.SETTINGS.wr_data.cfar_kind & hwif_out.SETTINGS.wr_biten.cfar_kind);
      cand.clutter_removal = (pend_q.clutter_removal & ~hwif_out.SETTINGS.wr_biten.clutter_removal)
                           | (hwif_out.SETTINGS.wr_data.clutter_removal
                              & hwif_out.SETTINGS.wr_biten.clutter_removal);
      cand.max_detections = (pend_q.max_detections & ~hwif_out.SETTINGS.wr_biten.max_detections)
                          | (hwif_out.SETTINGS.wr_data.max_detections
                             & hwif_out.SETTINGS.wr_biten.max_detections);
    end
    if (scale_wr) begin
      cand.cfar_scale = (pend_q.cfar_scale & ~hwif_out.CFAR_SCALE.wr_biten.scale)
                      | (hwif_out.CFAR_SCALE.wr_data.scale & hwif_out.CFAR_SCALE.wr_biten.scale);
    end
    if (pkt_wr) begin
      cand.packet_words = (pend_q.packet_words & ~hwif_out.PACKET.wr_biten.words)
                        | (hwif_out.PACKET.wr_data.words & hwif_out.PACKET.wr_biten.words);
    end
  end
  wire refused = !legal(cand.cfar_kind, cand.max_detections, cand.packet_words);

  always_ff @(posedge clk) begin
    if (rst)           pend_q <= RESET_SET;
    else if (!refused) pend_q <= cand;
  end

  // the shadow copy: the whole pending set, in the cycle after frame_start only
  always_ff @(posedge clk) begin
    if (rst)              active_q <= RESET_SET;
    else if (frame_start) active_q <= pend_q;
  end
  assign cfg_cfar_kind       = active_q.cfar_kind;
  assign cfg_clutter_removal = active_q.clutter_removal;
  assign cfg_max_detections  = active_q.max_detections;
  assign cfg_cfar_scale      = active_q.cfar_scale;
  assign cfg_packet_words    = active_q.packet_words;

  // external registers answer in the cycle of the request
  always_comb begin
    hwif_in.SETTINGS.wr_ack   = set_wr;
    hwif_in.SETTINGS.rd_ack   = hwif_out.SETTINGS.req && !hwif_out.SETTINGS.req_is_wr;
    hwif_in.SETTINGS.rd_data  = '0;
    hwif_in.SETTINGS.rd_data.cfar_kind       = pend_q.cfar_kind;
    hwif_in.SETTINGS.rd_data.clutter_removal = pend_q.clutter_removal;
    hwif_in.SETTINGS.rd_data.max_detections  = pend_q.max_detections;
    hwif_in.CFAR_SCALE.wr_ack  = scale_wr;
    hwif_in.CFAR_SCALE.rd_ack  = hwif_out.CFAR_SCALE.req && !hwif_out.CFAR_SCALE.req_is_wr;
    hwif_in.CFAR_SCALE.rd_data = '0;
    hwif_in.CFAR_SCALE.rd_data.scale = pend_q.cfar_scale;
    hwif_in.PACKET.wr_ack      = pkt_wr;
    hwif_in.PACKET.rd_ack      = hwif_out.PACKET.req && !hwif_out.PACKET.req_is_wr;
    hwif_in.PACKET.rd_data     = '0;
    hwif_in.PACKET.rd_data.words = pend_q.packet_words;
  end

  // refused writes never reach the pending set, so it is always legal (and so the active set)
  wire pend_legal = legal(pend_q.cfar_kind, pend_q.max_detections, pend_q.packet_words);
`ifdef FORMAL
  always_comb if (!rst) assert (pend_legal);
`elsif SYNTHESIS
  wire unused_pend_legal = pend_legal;
`else
  always_ff @(posedge clk) begin
    if (!rst) assert (pend_legal) else $error("%m: an out-of-range value reached the settings");
  end
`endif

  // ---- read-only registers, counters, sticky flags ----------------------------------------
  always_comb begin
    hwif_in.CAPS.max_detections.next         = 16'(MAX_DETECTIONS);
    hwif_in.CAPS.packet_words.next           = 16'(PACKET_WORDS);
    hwif_in.ACTIVE_SETTINGS.cfar_kind.next       = cfg_cfar_kind;
    hwif_in.ACTIVE_SETTINGS.clutter_removal.next = cfg_clutter_removal;
    hwif_in.ACTIVE_SETTINGS.max_detections.next  = cfg_max_detections;
    hwif_in.ACTIVE_CFAR_SCALE.scale.next     = cfg_cfar_scale;
    hwif_in.ACTIVE_PACKET.words.next         = cfg_packet_words;
    hwif_in.FRAMES.count.incr                = frame_done;
    hwif_in.PACKETS.count.incr               = packet_done;
    hwif_in.DROPS.count.incr                 = drop;
    hwif_in.ERRORS.count.incr                = error;
    hwif_in.CFG_ERRORS.count.incr            = refused;
    hwif_in.STATUS.frame_done.hwset          = frame_done;
    hwif_in.STATUS.drop.hwset                = drop;
    hwif_in.STATUS.error.hwset               = error;
    hwif_in.STATUS.cfg_error.hwset           = refused;
  end

  wire [3:0] flags  = {hwif_out.STATUS.cfg_error.value, hwif_out.STATUS.error.value,
                       hwif_out.STATUS.drop.value, hwif_out.STATUS.frame_done.value};
  wire [3:0] enable = {hwif_out.IRQ_ENABLE.cfg_error.value, hwif_out.IRQ_ENABLE.error.value,
                       hwif_out.IRQ_ENABLE.drop.value, hwif_out.IRQ_ENABLE.frame_done.value};
  always_ff @(posedge clk) begin
    if (rst) irq <= 1'b0;
    else     irq <= |(flags & enable);
  end

endmodule

`default_nettype wire
