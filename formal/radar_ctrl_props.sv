// SPDX-License-Identifier: Apache-2.0
// Formal harness of radar_ctrl (formal/radar_ctrl.sby): the wrapper with the generated
// register block, small bounds (MAX_DETECTIONS = 5, PACKET_WORDS 3..8, kinds CA and OS,
// 3 scales of 12 bits), every input free.
//   - AXI4-Lite handshakes (f_axis_port per channel): AW, W, AR assumed to follow the rules
//     (VALID held until READY, payload stable), B and R asserted to;
//   - one response per request: B beats never exceed accepted AW or W beats, R beats never
//     exceed accepted AR beats, and at most 2 requests of each kind wait for their response;
//   - the shadow rule: each consumer's cfg_* outputs change only in the cycle after its frame
//     start (clutter removal: removal_start; kind, local max, detections, scales:
//     detect_start; packet words: packet_start) or reset, and the active set is always legal
//     (kind 0/3, 1..5 detections, 3..8 packet words, scales below 2^12), what the wrapper's
//     own invariant (pending set always legal) implies;
//   - the packet length made active at a packet_start is pend_packet_words of that cycle
//     (what the top's packetizer takes with a frame's first word), and pend_packet_words is
//     always legal.
`default_nettype none

module radar_ctrl_props #(
  localparam int AW = radar_regs_pkg::RADAR_REGS_MIN_ADDR_WIDTH
) (
  input wire logic        clk,
  input wire logic        rst,
  input wire logic        s_axil_awvalid,
  input wire logic [AW-1:0] s_axil_awaddr,
  input wire logic [2:0]  s_axil_awprot,
  input wire logic        s_axil_wvalid,
  input wire logic [31:0] s_axil_wdata,
  input wire logic [3:0]  s_axil_wstrb,
  input wire logic        s_axil_bready,
  input wire logic        s_axil_arvalid,
  input wire logic [AW-1:0] s_axil_araddr,
  input wire logic [2:0]  s_axil_arprot,
  input wire logic        s_axil_rready,
  input wire logic        removal_start,
  input wire logic        detect_start,
  input wire logic        packet_start,
  input wire logic        frame_done,
  input wire logic        packet_done,
  input wire logic        drop,
  input wire logic        error
);
  localparam int MAXD = 5, WORDS = 8, WORDS_MIN = 3, NSC = 3, SCW = 12;

  logic        s_axil_awready, s_axil_wready, s_axil_bvalid, s_axil_arready, s_axil_rvalid;
  logic [1:0]  s_axil_bresp, s_axil_rresp;
  logic [31:0] s_axil_rdata;
  logic [1:0]  cfg_cfar_kind;
  logic        cfg_clutter_removal, cfg_local_max, irq;
  logic [15:0] cfg_max_detections, cfg_packet_words, pend_packet_words;
  logic [NSC*SCW-1:0] cfg_cfar_scale;

  radar_ctrl #(.MAX_DETECTIONS(MAXD), .PACKET_WORDS(WORDS), .PACKET_WORDS_MIN(WORDS_MIN),
               .CFAR_KINDS(4'b1001), .N_SCALES(NSC), .SCALE_W(SCW), .CFAR_KIND(3),
               .CFAR_SCALE(32'h0000_0100)) dut (
    .clk, .rst,
    .s_axil_awvalid, .s_axil_awready, .s_axil_awaddr, .s_axil_awprot,
    .s_axil_wvalid, .s_axil_wready, .s_axil_wdata, .s_axil_wstrb,
    .s_axil_bvalid, .s_axil_bready, .s_axil_bresp,
    .s_axil_arvalid, .s_axil_arready, .s_axil_araddr, .s_axil_arprot,
    .s_axil_rvalid, .s_axil_rready, .s_axil_rdata, .s_axil_rresp,
    .removal_start, .detect_start, .packet_start, .frame_done, .packet_done, .drop, .error,
    .cfg_cfar_kind, .cfg_local_max, .cfg_clutter_removal, .cfg_max_detections,
    .cfg_cfar_scale, .cfg_packet_words, .pend_packet_words, .irq);

  initial assume (rst);

  logic [7:0] n_aw, n_w, n_b, n_ar, n_r;
  f_axis_port #(.PAYLOAD_W(AW + 3), .ASSUME(1'b1)) u_aw (
    .clk, .rst, .tvalid(s_axil_awvalid), .tready(s_axil_awready),
    .payload({s_axil_awprot, s_axil_awaddr}), .beats(n_aw));
  f_axis_port #(.PAYLOAD_W(36), .ASSUME(1'b1)) u_w (
    .clk, .rst, .tvalid(s_axil_wvalid), .tready(s_axil_wready),
    .payload({s_axil_wstrb, s_axil_wdata}), .beats(n_w));
  f_axis_port #(.PAYLOAD_W(AW + 3), .ASSUME(1'b1)) u_ar (
    .clk, .rst, .tvalid(s_axil_arvalid), .tready(s_axil_arready),
    .payload({s_axil_arprot, s_axil_araddr}), .beats(n_ar));
`ifndef SHADOW_ONLY  // the prove task: the shadow rule alone (the block's state makes the
                    // response-channel rules non-inductive; the bmc task checks them)
  f_axis_port #(.PAYLOAD_W(2)) u_b (
    .clk, .rst, .tvalid(s_axil_bvalid), .tready(s_axil_bready), .payload(s_axil_bresp),
    .beats(n_b));
  f_axis_port #(.PAYLOAD_W(34)) u_r (
    .clk, .rst, .tvalid(s_axil_rvalid), .tready(s_axil_rready),
    .payload({s_axil_rresp, s_axil_rdata}), .beats(n_r));
`endif

  localparam int DW = 2 + 1 + 16 + NSC * SCW;
  logic          past = 1'b0;
  logic          rs_q, ds_q, ps_q, rst_q, rem_q;
  logic [DW-1:0] det_q;
  logic [15:0]   words_q, pend_words_q;
  wire  [DW-1:0] det = {cfg_cfar_kind, cfg_local_max, cfg_max_detections, cfg_cfar_scale};
  always_ff @(posedge clk) begin
    past    <= 1'b1;
    rs_q    <= removal_start;
    ds_q    <= detect_start;
    ps_q    <= packet_start;
    rst_q   <= rst;
    rem_q   <= cfg_clutter_removal;
    det_q   <= det;
    words_q <= cfg_packet_words;
    pend_words_q <= pend_packet_words;
  end

  always_comb if (past && !rst) begin
`ifndef SHADOW_ONLY
    // one response per request, at most 3 waiting (2 in the block, 1 in its skid register)
    assert (8'(n_aw - n_b) <= 8'd3);
    assert (8'(n_w - n_b) <= 8'd3);
    assert (8'(n_ar - n_r) <= 8'd3);
    assert (s_axil_bresp == 2'b00 && s_axil_rresp == 2'b00);
`endif
    // shadow rule, per consumer
    if (!rs_q && !rst_q) assert (cfg_clutter_removal == rem_q);
    if (!ds_q && !rst_q) assert (det == det_q);
    if (!ps_q && !rst_q) assert (cfg_packet_words == words_q);
    // the packet length copied at a packet_start is the pending one of that cycle, which the
    // top's packetizer takes with a frame's first word
    if (ps_q && !rst_q) assert (cfg_packet_words == pend_words_q);
    assert (cfg_cfar_kind == 2'd0 || cfg_cfar_kind == 2'd3);
    assert (cfg_max_detections >= 16'd1 && cfg_max_detections <= 16'(MAXD));
    assert (cfg_packet_words >= 16'(WORDS_MIN) && cfg_packet_words <= 16'(WORDS));
    assert (pend_packet_words >= 16'(WORDS_MIN) && pend_packet_words <= 16'(WORDS));
  end

  always_comb if (past && !rst) begin
    cover (ds_q && det != det_q);                 // a new detector setting applied
    cover (ps_q && cfg_packet_words != words_q);  // a new packet length applied
    cover (irq);
  end
endmodule

`default_nettype wire
