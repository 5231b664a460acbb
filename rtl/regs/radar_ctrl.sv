// SPDX-License-Identifier: Apache-2.0
// Control and status plane of the radar processor (docs/regs.md): the AXI4-Lite register
// block generated from rtl/regs/radar_regs.rdl (radar_regs) plus what the generator cannot
// express:
//   - the settings (SETTINGS, PACKET and the CFAR_SCALE array are external registers of
//     radar_regs, held here): each write is checked whole, after its byte strobes are merged
//     with the old value; a write holding an out-of-range field (a CFAR kind not built in,
//     max_detections 0 or above MAX_DETECTIONS, packet words outside PACKET_WORDS_MIN ..
//     PACKET_WORDS, a scale of SCALE_W or more bits, a scale entry from N_SCALES on) is
//     refused whole (the register keeps its value), counted in CFG_ERRORS and sets
//     STATUS.cfg_error;
//   - the shadow rule, per consumer: the pending settings (always legal) are copied to the
//     active ones, the cfg_* outputs, in the cycle after that consumer's frame-start pulse
//     and at no other time (a write accepted in that same cycle waits for the next one):
//     clutter_removal at removal_start, the detector's set (cfar_kind, local_max,
//     max_detections, the scales) at detect_start, packet words at packet_start;
//     pend_packet_words is the pending packet length itself (a register), for a consumer
//     that takes its setting in the frame-start cycle: what it takes there is what the
//     copy makes active at the end of that cycle (the packetizer, docs/regs.md);
//   - the event pulses (frame_done, packet_done, drop, error) feed the saturating counters
//     FRAMES, PACKETS, DROPS, ERRORS and the sticky write-one-to-clear STATUS flags (an event
//     in the cycle of the clearing write keeps its flag);
//   - irq: registered, high while any STATUS flag whose IRQ_ENABLE bit is set is high.
// Bit-accurate model: model/radar_ctrl.py. Everything is cleared by `rst` only.
`default_nettype none

module radar_ctrl #(
  parameter int          MAX_DETECTIONS   = 256,     // bound of SETTINGS.max_detections, reset
  parameter int          PACKET_WORDS     = 1024,    // bound of PACKET.words, reset value
  parameter int          PACKET_WORDS_MIN = 1,       // smallest legal PACKET.words
  parameter logic [3:0]  CFAR_KINDS       = 4'b0111, // bit k: CFAR kind k built in
  parameter int          N_SCALES         = 13,      // CFAR_SCALE entries (2*(G_R+T_R)+1)
  parameter int          SCALE_W          = 32,      // bits of a scale
  parameter int          CFAR_KIND        = 0,       // reset CFAR kind (0 CA 1 GO 2 SO 3 OS)
  parameter int unsigned CFAR_SCALE       = 0,       // reset threshold scale, every entry
  parameter bit          LOCAL_MAX        = 1'b0,    // reset local-maximum switch
  parameter bit          CLUTTER_REMOVAL  = 1'b0,    // reset static-clutter removal switch
  localparam int         ADDR_W           = radar_regs_pkg::RADAR_REGS_MIN_ADDR_WIDTH,
  localparam int         MAX_SCALES       = 61       // CFAR_SCALE entries of the map (mem)
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
  // frame starts of the settings' consumers: each set changes in the cycle after its pulse
  input  wire logic              removal_start,   // clutter_removal
  input  wire logic              detect_start,    // cfar_kind, local_max, max_detections,
                                                  // cfar_scale
  input  wire logic              packet_start,    // packet_words
  // event pulses from the datapath (one cycle each)
  input  wire logic              frame_done,
  input  wire logic              packet_done,
  input  wire logic              drop,
  input  wire logic              error,
  // active settings (each changes only in the cycle after its frame start)
  output logic [1:0]             cfg_cfar_kind,
  output logic                   cfg_local_max,
  output logic                   cfg_clutter_removal,
  output logic [15:0]            cfg_max_detections,
  // scale of range edge index e at bits e*SCALE_W (model.cfar_2d.pack_scale)
  output logic [N_SCALES*SCALE_W-1:0] cfg_cfar_scale,
  output logic [15:0]            cfg_packet_words,
  // the pending PACKET.words (a register): what cfg_packet_words becomes at the edge after
  // a packet_start cycle, so the length a frame taken in that cycle gets
  output logic [15:0]            pend_packet_words,
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
  if (PACKET_WORDS_MIN < 1 || PACKET_WORDS_MIN > PACKET_WORDS) begin : g_bad_packet_words_min
    $fatal(1, "%m: PACKET_WORDS_MIN=%0d must be 1..PACKET_WORDS=%0d", PACKET_WORDS_MIN,
           PACKET_WORDS);
  end
  if (CFAR_KINDS == 4'b0000) begin : g_bad_cfar_kinds
    $fatal(1, "%m: CFAR_KINDS=%0d must have a kind built in", CFAR_KINDS);
  end
  if (CFAR_KIND < 0 || CFAR_KIND > 3 || !CFAR_KINDS[CFAR_KIND[1:0]]) begin : g_bad_cfar_kind
    $fatal(1, "%m: CFAR_KIND=%0d must be a kind of CFAR_KINDS=%0d", CFAR_KIND, CFAR_KINDS);
  end
  if (N_SCALES < 1 || N_SCALES > MAX_SCALES) begin : g_bad_n_scales
    $fatal(1, "%m: N_SCALES=%0d must be 1..%0d (the CFAR_SCALE table)", N_SCALES, MAX_SCALES);
  end
  if (SCALE_W < 1 || SCALE_W > 32) begin : g_bad_scale_w
    $fatal(1, "%m: SCALE_W=%0d must be 1..32 (a 32-bit register)", SCALE_W);
  end
  if (SCALE_W < 32 && longint'(CFAR_SCALE) >= (64'd1 << SCALE_W)) begin : g_bad_cfar_scale
    $fatal(1, "%m: CFAR_SCALE=%0d does not fit SCALE_W=%0d bits", CFAR_SCALE, SCALE_W);
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
    logic        local_max;
    logic        clutter_removal;
    logic [15:0] max_detections;
    logic [15:0] packet_words;
  } settings_t;
  localparam settings_t RESET_SET = {2'(CFAR_KIND), LOCAL_MAX, CLUTTER_REMOVAL,
                                     16'(MAX_DETECTIONS), 16'(PACKET_WORDS)};
  localparam int SC_W = N_SCALES * 32;   // the scales, 32 bits an entry

  function automatic logic legal(input logic [1:0] kind, input logic [15:0] maxdet,
                                 input logic [15:0] words);
    legal = CFAR_KINDS[kind] && maxdet != '0 && 32'(maxdet) <= 32'(MAX_DETECTIONS)
            && 32'(words) >= 32'(PACKET_WORDS_MIN) && 32'(words) <= 32'(PACKET_WORDS);
  endfunction
  function automatic logic scale_ok(input logic [31:0] scale);
    scale_ok = (SCALE_W == 32) || ((scale >> SCALE_W) == '0);
  endfunction

  settings_t         pend_q, active_q, cand;
  logic [SC_W-1:0]   pend_sc_q, active_sc_q;
  logic              sc_wr, sc_bad;
  // byte-lane and unused address bits of the scale memories: accesses are whole words
  wire unused_sc = ^{hwif_out.CFAR_SCALE.addr[1:0], hwif_out.ACTIVE_CFAR_SCALE.addr[1:0],
                     hwif_out.ACTIVE_CFAR_SCALE.req_is_wr, hwif_out.ACTIVE_CFAR_SCALE.wr_data,
                     hwif_out.ACTIVE_CFAR_SCALE.wr_biten};

  wire set_wr = hwif_out.SETTINGS.req && hwif_out.SETTINGS.req_is_wr;
  wire pkt_wr = hwif_out.PACKET.req && hwif_out.PACKET.req_is_wr;

  // the settings as this cycle's write would leave them (byte strobes merged with the old
  // value); the write is refused whole when the result is not legal. The block decodes one
  // request at a time, so at most one of the settings registers is written in a cycle.
  always_comb begin
    cand = pend_q;
    if (set_wr) begin
      cand.cfar_kind = (pend_q.cfar_kind & ~hwif_out.SETTINGS.wr_biten.cfar_kind)
                     | (hwif_out.SETTINGS.wr_data.cfar_kind & hwif_out.SETTINGS.wr_biten.cfar_kind);
      cand.local_max = (pend_q.local_max & ~hwif_out.SETTINGS.wr_biten.local_max)
                     | (hwif_out.SETTINGS.wr_data.local_max & hwif_out.SETTINGS.wr_biten.local_max);
      cand.clutter_removal = (pend_q.clutter_removal & ~hwif_out.SETTINGS.wr_biten.clutter_removal)
                           | (hwif_out.SETTINGS.wr_data.clutter_removal
                              & hwif_out.SETTINGS.wr_biten.clutter_removal);
      cand.max_detections = (pend_q.max_detections & ~hwif_out.SETTINGS.wr_biten.max_detections)
                          | (hwif_out.SETTINGS.wr_data.max_detections
                             & hwif_out.SETTINGS.wr_biten.max_detections);
    end
    if (pkt_wr) begin
      cand.packet_words = (pend_q.packet_words & ~hwif_out.PACKET.wr_biten.words)
                        | (hwif_out.PACKET.wr_data.words & hwif_out.PACKET.wr_biten.words);
    end
  end

  // scale entries (CFAR_SCALE, an external memory: byte address hwif_out.CFAR_SCALE.addr):
  // entry e < N_SCALES holds a scale; a write from N_SCALES on is refused
  wire [5:0]  sc_entry = hwif_out.CFAR_SCALE.addr[7:2];
  wire        sc_exists = 32'(sc_entry) < 32'(N_SCALES);
  // (entry selects by comparison, not an index modulo N_SCALES: a 13-entry modulo is a
  // divider's carry chains on the write path)
  logic [31:0] sc_old;
  always_comb begin
    sc_old = '0;
    for (int e = 0; e < N_SCALES; e++)
      if (sc_entry == 6'(e)) sc_old = pend_sc_q[e * 32 +: 32];
  end
  wire [31:0] sc_new = (sc_old & ~hwif_out.CFAR_SCALE.wr_biten)
                     | (hwif_out.CFAR_SCALE.wr_data & hwif_out.CFAR_SCALE.wr_biten);
  assign sc_wr  = hwif_out.CFAR_SCALE.req && hwif_out.CFAR_SCALE.req_is_wr;
  assign sc_bad = !sc_exists || !scale_ok(sc_new);
  wire sc_take = sc_wr && !sc_bad;
  wire set_bad = (set_wr || pkt_wr) && !legal(cand.cfar_kind, cand.max_detections,
                                              cand.packet_words);
  wire refused = set_bad || (sc_wr && sc_bad);

  // each entry loads on its own decode (no table-wide enable)
  always_ff @(posedge clk) begin
    if (rst) begin
      pend_q    <= RESET_SET;
      pend_sc_q <= {N_SCALES{32'(CFAR_SCALE)}};
    end else begin
      if ((set_wr || pkt_wr) && !set_bad) pend_q <= cand;
      for (int e = 0; e < N_SCALES; e++)
        if (sc_take && sc_entry == 6'(e)) pend_sc_q[e * 32 +: 32] <= sc_new;
    end
  end

  // the shadow copies: each consumer's settings, in the cycle after its frame start only
  always_ff @(posedge clk) begin
    if (rst) begin
      active_q    <= RESET_SET;
      active_sc_q <= {N_SCALES{32'(CFAR_SCALE)}};
    end else begin
      if (removal_start) active_q.clutter_removal <= pend_q.clutter_removal;
      if (detect_start) begin
        active_q.cfar_kind      <= pend_q.cfar_kind;
        active_q.local_max      <= pend_q.local_max;
        active_q.max_detections <= pend_q.max_detections;
        active_sc_q             <= pend_sc_q;
      end
      if (packet_start) active_q.packet_words <= pend_q.packet_words;
    end
  end
  assign cfg_cfar_kind       = active_q.cfar_kind;
  assign cfg_local_max       = active_q.local_max;
  assign cfg_clutter_removal = active_q.clutter_removal;
  assign cfg_max_detections  = active_q.max_detections;
  assign cfg_packet_words    = active_q.packet_words;
  assign pend_packet_words   = pend_q.packet_words;
  always_comb begin
    for (int e = 0; e < N_SCALES; e++)
      cfg_cfar_scale[e * SCALE_W +: SCALE_W] = active_sc_q[e * 32 +: SCALE_W];
  end

  // external registers and memories: the regblock registers each request (retime_external,
  // tools/gen_regs.py); they answer in the cycle it arrives
  wire [5:0] act_entry = hwif_out.ACTIVE_CFAR_SCALE.addr[7:2];
  always_comb begin
    hwif_in.SETTINGS.wr_ack   = set_wr;
    hwif_in.SETTINGS.rd_ack   = hwif_out.SETTINGS.req && !hwif_out.SETTINGS.req_is_wr;
    hwif_in.SETTINGS.rd_data  = '0;
    hwif_in.SETTINGS.rd_data.cfar_kind       = pend_q.cfar_kind;
    hwif_in.SETTINGS.rd_data.local_max       = pend_q.local_max;
    hwif_in.SETTINGS.rd_data.clutter_removal = pend_q.clutter_removal;
    hwif_in.SETTINGS.rd_data.max_detections  = pend_q.max_detections;
    hwif_in.PACKET.wr_ack      = pkt_wr;
    hwif_in.PACKET.rd_ack      = hwif_out.PACKET.req && !hwif_out.PACKET.req_is_wr;
    hwif_in.PACKET.rd_data     = '0;
    hwif_in.PACKET.rd_data.words = pend_q.packet_words;
    hwif_in.CFAR_SCALE.wr_ack  = sc_wr;
    hwif_in.CFAR_SCALE.rd_ack  = hwif_out.CFAR_SCALE.req && !hwif_out.CFAR_SCALE.req_is_wr;
    hwif_in.CFAR_SCALE.rd_data = sc_old;
    // read only: the block decodes reads there only
    hwif_in.ACTIVE_CFAR_SCALE.wr_ack  = 1'b0;
    hwif_in.ACTIVE_CFAR_SCALE.rd_ack  = hwif_out.ACTIVE_CFAR_SCALE.req;
    hwif_in.ACTIVE_CFAR_SCALE.rd_data = '0;
    for (int e = 0; e < N_SCALES; e++)
      if (act_entry == 6'(e)) hwif_in.ACTIVE_CFAR_SCALE.rd_data = active_sc_q[e * 32 +: 32];
  end

  // refused writes never reach the pending set, so it is always legal (and so the active set)
  logic pend_sc_ok;
  always_comb begin
    pend_sc_ok = 1'b1;
    for (int e = 0; e < N_SCALES; e++)
      if (!scale_ok(pend_sc_q[e * 32 +: 32])) pend_sc_ok = 1'b0;
  end
  wire pend_legal = legal(pend_q.cfar_kind, pend_q.max_detections, pend_q.packet_words)
                    && pend_sc_ok;
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
    hwif_in.CAPS2.cfar_kinds.next            = CFAR_KINDS;
    hwif_in.CAPS2.cfar_scales.next           = 8'(N_SCALES);
    hwif_in.CAPS2.packet_words_min.next      = 16'(PACKET_WORDS_MIN);
    hwif_in.ACTIVE_SETTINGS.cfar_kind.next       = cfg_cfar_kind;
    hwif_in.ACTIVE_SETTINGS.local_max.next       = cfg_local_max;
    hwif_in.ACTIVE_SETTINGS.clutter_removal.next = cfg_clutter_removal;
    hwif_in.ACTIVE_SETTINGS.max_detections.next  = cfg_max_detections;
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
