// SPDX-License-Identifier: Apache-2.0
// Formal harness of frame_store_axi (formal/frame_store_axi.sby): 1 TX x 1 RX x 4 range bins
// x 2 chirps, DATA_W 32 (64-bit words, 8 a frame), TILE_R 4 (two-beat write bursts, one
// four-beat read burst per frame), 128-bit AXI, 2 bursts outstanding, WFIFO_DEPTH 4. Written against the block's
// ports and parameters as they are; the memory side is free within the AXI4 rules.
//   - s_axis, m_axis: the shared f_axis_port set (assumed / asserted);
//   - the AXI4 master port: the shared f_axi4_master set (every channel's handshake, WLAST
//     on the burst's last beat, outstanding bursts <= MAX_OUTSTANDING, 4 KiB, W not ahead);
//   - no word created or lost on the way: words in >= 2 x W beats (2 words per 128-bit beat)
//     >= words in - 12 (FIFO of 4 beats, both gearboxes); words out <= 2 x R beats;
//   - output framing: TLAST on every N_DOPPLER-th word, TUSER[0] on the first word of each
//     frame; frames_out <= frames_in;
//   - status_mem_error is exactly "some B or R beat had an error response".
// Data: only the low 2 bits of each input word and R beat are free (the rest tied to zero):
// the properties are about control, and the 124 constant bits of every FIFO and buffer
// entry are then optimised away (bmc depth 20 in minutes instead of an hour); the data path
// itself (gearboxes, FIFO: any word out unchanged and in order) is proven unbounded in
// frame_store_gearbox.sby and frame_store_fifo.sby.
`default_nettype none

module frame_store_axi_props (
  input wire logic         clk,
  input wire logic         rst,
  input wire logic [1:0]   s_axis_tdata,   // low bits of the word (the rest are zero)
  input wire logic         s_axis_tvalid,
  input wire logic         s_axis_tlast,
  input wire logic         m_axis_tready,
  input wire logic         awready,
  input wire logic         wready,
  input wire logic         bid,
  input wire logic [1:0]   bresp,
  input wire logic         bvalid,
  input wire logic         arready,
  input wire logic         rid,
  input wire logic [1:0]   rdata,          // low bits of the R beat (the rest are zero)
  input wire logic [1:0]   rresp,
  input wire logic         rlast,
  input wire logic         rvalid
);
  localparam int N_RANGE = 4, N_DOPPLER = 2, WPB = 2;   // words per AXI beat

  logic         s_axis_tready, m_axis_tvalid, m_axis_tlast;
  logic [63:0]  m_axis_tdata;
  logic [0:0]   m_axis_tuser;
  logic         awid, arid, awlock, arlock, awvalid, wvalid, wlast, bready, arvalid, rready;
  logic [31:0]  awaddr, araddr;
  logic [7:0]   awlen, arlen;
  logic [2:0]   awsize, arsize, awprot, arprot;
  logic [1:0]   awburst, arburst;
  logic [3:0]   awcache, arcache;
  logic [127:0] wdata;
  logic [15:0]  wstrb;
  logic         framing, mem_err;
  logic [31:0]  framing_cnt, mem_err_cnt, frames_in, frames_out;

  frame_store_axi #(
    .NUM_TX(1), .NUM_RX(1), .N_RANGE(N_RANGE), .N_DOPPLER(N_DOPPLER), .DATA_W(32),
    .TILE_R(4), .AXI_DATA_W(128), .AXI_ADDR_W(32), .AXI_ID_W(1), .MEM_BASE(0),
    .MAX_OUTSTANDING(2), .WFIFO_DEPTH(4)
  ) dut (
    .clk, .rst,
    .s_axis_tdata(64'(s_axis_tdata)), .s_axis_tvalid, .s_axis_tready, .s_axis_tlast,
    .m_axis_tdata, .m_axis_tvalid, .m_axis_tready, .m_axis_tlast, .m_axis_tuser,
    .m_axi_mem_awid(awid), .m_axi_mem_awaddr(awaddr), .m_axi_mem_awlen(awlen),
    .m_axi_mem_awsize(awsize), .m_axi_mem_awburst(awburst), .m_axi_mem_awlock(awlock),
    .m_axi_mem_awcache(awcache), .m_axi_mem_awprot(awprot), .m_axi_mem_awvalid(awvalid),
    .m_axi_mem_awready(awready),
    .m_axi_mem_wdata(wdata), .m_axi_mem_wstrb(wstrb), .m_axi_mem_wlast(wlast),
    .m_axi_mem_wvalid(wvalid), .m_axi_mem_wready(wready),
    .m_axi_mem_bid(bid), .m_axi_mem_bresp(bresp), .m_axi_mem_bvalid(bvalid),
    .m_axi_mem_bready(bready),
    .m_axi_mem_arid(arid), .m_axi_mem_araddr(araddr), .m_axi_mem_arlen(arlen),
    .m_axi_mem_arsize(arsize), .m_axi_mem_arburst(arburst), .m_axi_mem_arlock(arlock),
    .m_axi_mem_arcache(arcache), .m_axi_mem_arprot(arprot), .m_axi_mem_arvalid(arvalid),
    .m_axi_mem_arready(arready),
    .m_axi_mem_rid(rid), .m_axi_mem_rdata(128'(rdata)), .m_axi_mem_rresp(rresp),
    .m_axi_mem_rlast(rlast), .m_axi_mem_rvalid(rvalid), .m_axi_mem_rready(rready),
    .status_framing_error(framing), .framing_error_count(framing_cnt),
    .status_mem_error(mem_err), .mem_error_count(mem_err_cnt), .frames_in, .frames_out);

  initial assume (rst);

  logic [7:0] n_in, n_out, w_beats, r_beats;
  f_axis_port #(.PAYLOAD_W(65), .ASSUME(1'b1)) u_s (
    .clk, .rst, .tvalid(s_axis_tvalid), .tready(s_axis_tready),
    .payload({s_axis_tlast, 64'(s_axis_tdata)}), .beats(n_in));
  f_axis_port #(.PAYLOAD_W(66)) u_m (
    .clk, .rst, .tvalid(m_axis_tvalid), .tready(m_axis_tready),
    .payload({m_axis_tuser, m_axis_tlast, m_axis_tdata}), .beats(n_out));
  // (one read burst per frame: two reads outstanding need two frames, beyond the cover bound)
  f_axi4_master #(.ADDR_W(32), .DATA_W(128), .ID_W(1), .MAX_OUT(2), .COVER_R_MAX(1'b0)) u_axi (
    .clk, .rst,
    .awid, .awaddr, .awlen, .awsize, .awburst, .awvalid, .awready,
    .wdata, .wstrb, .wlast, .wvalid, .wready,
    .bid, .bresp, .bvalid, .bready,
    .arid, .araddr, .arlen, .arsize, .arburst, .arvalid, .arready,
    .rid, .rdata(128'(rdata)), .rresp, .rlast, .rvalid, .rready,
    .w_beats, .r_beats);

  logic past = 1'b0;
  logic f_err;
  always_ff @(posedge clk) begin
    past <= 1'b1;
    if (rst) f_err <= 1'b0;
    else if ((bvalid && bready && bresp != 2'b00) || (rvalid && rready && rresp != 2'b00))
      f_err <= 1'b1;
  end

  // (8-bit counters: the bounds are checked within the bmc depth, before they wrap)
  wire [9:0] w_words = 10'(w_beats) * 10'(WPB);
  wire [9:0] r_words = 10'(r_beats) * 10'(WPB);
  always_comb if (past && !rst) begin
    assert (w_words <= 10'(n_in));
    assert (10'(n_in) <= w_words + 10'd12);
    assert (10'(n_out) <= r_words);
    if (m_axis_tvalid) begin
      assert (n_out != 8'(r_words));
      assert (m_axis_tlast == (n_out[0] == 1'b1));                    // N_DOPPLER = 2
      assert (m_axis_tuser[0] == (n_out[2:0] == 3'd0));               // 8 words a frame
    end
    assert (frames_out <= frames_in);
    assert (mem_err == f_err);
    assert ((mem_err_cnt != 0) == f_err);
  end
  always_comb if (past && !rst) begin
    cover (mem_err);
  end
  wire unused = ^{framing, framing_cnt, awlock, arlock, awcache, arcache, awprot, arprot};
endmodule

`default_nettype wire
