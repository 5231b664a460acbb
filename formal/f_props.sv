// SPDX-License-Identifier: Apache-2.0
// Shared formal property sets of the harnesses in formal/ (the one place they are written):
//
//   f_axis_port  one AXI4-Stream port: the handshake rules (rtl/common/axis_checker.sv:
//                TVALID held until TREADY, payload stable while stalled; ASSUME = 1 on a
//                port the environment drives, asserted otherwise), a beat counter the
//                harness ties to the block's other port (no beat created or lost), covers:
//                a stalled beat and a completed beat (the port is not vacuous);
//   f_vld_pipe   one en/vld/pos pipeline stage of the FFT (not AXI-Stream: every enabled
//                cycle moves every stage): out_vld is in_vld exactly LAT enabled cycles
//                later, out_pos likewise, nothing created or lost;
//   f_axi4_master  an AXI4 master port: every channel (AW, W, B, AR, R) under the handshake
//                rules (asserted on AW/W/AR, assumed on B/R), WLAST exactly on the last beat
//                of its burst (AWLEN + 1 beats), W at most one burst ahead of AW (the burst
//                whose AW is presented), no more than MAX_OUT writes (AW without B) and reads
//                (AR without last R) outstanding, no burst across 4 KiB; the slave is assumed
//                to answer only accepted bursts (B after AW and WLAST, R after AR) with RLAST
//                on beat ARLEN; R beats are counted per burst.
`default_nettype none

module f_axis_port #(
  parameter int PAYLOAD_W = 1,
  parameter bit ASSUME    = 1'b0,
  parameter int CNT_W     = 8,
  parameter bit COVER     = 1'b1   // 0: the harness' bound is too short to reach a beat
) (
  input  wire logic                 clk,
  input  wire logic                 rst,
  input  wire logic                 tvalid,
  input  wire logic                 tready,
  input  wire logic [PAYLOAD_W-1:0] payload,
  output logic      [CNT_W-1:0]     beats     // beats since reset (wraps)
);
  axis_checker #(.PAYLOAD_W(PAYLOAD_W), .ASSUME(ASSUME)) u_chk (
    .clk, .rst, .tvalid, .tready, .payload);

  always_ff @(posedge clk) begin
    if (rst) beats <= '0;
    else if (tvalid && tready) beats <= beats + 1'b1;
  end

  if (COVER) begin : g_cover
    always_comb if (!rst) begin
      cover (tvalid && !tready);
      cover (tvalid && tready && beats != '0);
    end
  end
endmodule

module f_vld_pipe #(
  parameter int LAT   = 1,     // enabled cycles from in to out
  parameter int POS_W = 1,
  // > 0: assume en is low at most FAIR cycles in a row (for k-induction: every register of
  // a stage loads only on en, so a longer stall changes nothing; 0: en free)
  parameter int FAIR  = 0
) (
  input  wire logic             clk,
  input  wire logic             rst,
  input  wire logic             en,
  input  wire logic             in_vld,
  input  wire logic [POS_W-1:0] in_pos,
  input  wire logic             out_vld,
  input  wire logic [POS_W-1:0] out_pos
);
  logic             past = 1'b0;
  logic [LAT-1:0]   vld_q;
  logic [POS_W-1:0] pos_q [LAT];
  logic [7:0]       n_in, n_out;
  logic [3:0]       idle_q;        // cycles in a row with en low

  if (FAIR > 0) begin : g_fair
    always_ff @(posedge clk) idle_q <= en ? 4'd0 : (idle_q == 4'd15 ? idle_q : idle_q + 4'd1);
    always_comb assume (en || idle_q < 4'(FAIR));
  end else begin : g_free
    always_ff @(posedge clk) idle_q <= 4'd0;
  end

  always_ff @(posedge clk) begin
    past <= 1'b1;
    if (en) begin
      pos_q[0] <= in_pos;
      for (int k = 1; k < LAT; k++) pos_q[k] <= pos_q[k-1];
    end
    if (rst) begin
      vld_q  <= '0;
      n_in   <= '0;
      n_out  <= '0;
    end else if (en) begin
      vld_q  <= {vld_q[LAT-2 >= 0 ? LAT-2 : 0:0], in_vld};
      n_in   <= n_in + 8'(in_vld);
      n_out  <= n_out + 8'(out_vld);
    end
  end

  always_comb if (past && !rst) begin
    assert (out_vld == vld_q[LAT-1]);
    if (out_vld) assert (out_pos == pos_q[LAT-1]);
    // counting: what went in is out or in one of the LAT stages
    assert (8'(n_in - n_out) == 8'($countones(vld_q)));
  end
  always_comb if (past && !rst) begin
    cover (out_vld && !en);
    cover (out_vld && n_out == 8'd3);
  end
endmodule

module f_axi4_master #(
  parameter int ADDR_W  = 32,
  parameter int DATA_W  = 128,
  parameter int ID_W    = 1,
  parameter int MAX_OUT = 2,     // bursts outstanding per direction, power of two
  parameter bit RLAST_OK = 1'b1, // assume the slave puts RLAST on beat ARLEN
  parameter bit COVER_R_MAX = 1'b1 // cover MAX_OUT reads outstanding (0: the bound is short)
) (
  input  wire logic              clk,
  input  wire logic              rst,
  input  wire logic [ID_W-1:0]   awid,
  input  wire logic [ADDR_W-1:0] awaddr,
  input  wire logic [7:0]        awlen,
  input  wire logic [2:0]        awsize,
  input  wire logic [1:0]        awburst,
  input  wire logic              awvalid,
  input  wire logic              awready,
  input  wire logic [DATA_W-1:0] wdata,
  input  wire logic [DATA_W/8-1:0] wstrb,
  input  wire logic              wlast,
  input  wire logic              wvalid,
  input  wire logic              wready,
  input  wire logic [ID_W-1:0]   bid,
  input  wire logic [1:0]        bresp,
  input  wire logic              bvalid,
  input  wire logic              bready,
  input  wire logic [ID_W-1:0]   arid,
  input  wire logic [ADDR_W-1:0] araddr,
  input  wire logic [7:0]        arlen,
  input  wire logic [2:0]        arsize,
  input  wire logic [1:0]        arburst,
  input  wire logic              arvalid,
  input  wire logic              arready,
  input  wire logic [ID_W-1:0]   rid,
  input  wire logic [DATA_W-1:0] rdata,
  input  wire logic [1:0]        rresp,
  input  wire logic              rlast,
  input  wire logic              rvalid,
  input  wire logic              rready,
  output logic      [7:0]        w_beats,    // W beats since reset (wraps)
  output logic      [7:0]        r_beats     // R beats since reset (wraps)
);
  localparam int QB = (MAX_OUT > 1) ? $clog2(MAX_OUT) : 1;
  localparam int QN = 1 << QB;

  logic [7:0] aw_n, w_bursts, b_n, ar_n, r_bursts;
  logic [7:0] aw_bc, wb_c, ar_bc, rb_c;   // beat counters of each channel
  logic [7:0] w_beat, r_beat;             // beat within the current W / R burst
  logic [7:0] awlen_q [QN];               // AWLEN / ARLEN of accepted bursts, by index mod QN
  logic [7:0] arlen_q [QN];
  logic [7:0] w_len, r_len;
  logic       past = 1'b0;

  wire aw_hs = awvalid && awready;
  wire w_hs  = wvalid && wready;
  wire b_hs  = bvalid && bready;
  wire ar_hs = arvalid && arready;
  wire r_hs  = rvalid && rready;

  // channel handshake rules: valid held until ready, payload stable while stalled
  axis_checker #(.PAYLOAD_W(ID_W + ADDR_W + 8 + 3 + 2)) u_chk_aw (
    .clk, .rst, .tvalid(awvalid), .tready(awready),
    .payload({awid, awaddr, awlen, awsize, awburst}));
  axis_checker #(.PAYLOAD_W(DATA_W + DATA_W / 8 + 1)) u_chk_w (
    .clk, .rst, .tvalid(wvalid), .tready(wready), .payload({wdata, wstrb, wlast}));
  axis_checker #(.PAYLOAD_W(ID_W + 2), .ASSUME(1'b1)) u_chk_b (
    .clk, .rst, .tvalid(bvalid), .tready(bready), .payload({bid, bresp}));
  axis_checker #(.PAYLOAD_W(ID_W + ADDR_W + 8 + 3 + 2)) u_chk_ar (
    .clk, .rst, .tvalid(arvalid), .tready(arready),
    .payload({arid, araddr, arlen, arsize, arburst}));
  axis_checker #(.PAYLOAD_W(ID_W + DATA_W + 2 + 1), .ASSUME(1'b1)) u_chk_r (
    .clk, .rst, .tvalid(rvalid), .tready(rready), .payload({rid, rdata, rresp, rlast}));

  always_ff @(posedge clk) begin
    past <= 1'b1;
    if (aw_hs) awlen_q[aw_n[QB-1:0]] <= awlen;
    if (ar_hs) arlen_q[ar_n[QB-1:0]] <= arlen;
    if (rst) begin
      {aw_n, w_bursts, b_n, ar_n, r_bursts} <= '0;
      {w_beat, r_beat, w_beats, r_beats} <= '0;
    end else begin
      if (aw_hs) aw_n <= aw_n + 8'd1;
      if (ar_hs) ar_n <= ar_n + 8'd1;
      if (b_hs)  b_n  <= b_n + 8'd1;
      if (w_hs) begin
        w_beats <= w_beats + 8'd1;
        w_beat  <= wlast ? 8'd0 : w_beat + 8'd1;
        if (wlast) w_bursts <= w_bursts + 8'd1;
      end
      if (r_hs) begin
        r_beats <= r_beats + 8'd1;
        r_beat  <= rlast ? 8'd0 : r_beat + 8'd1;
        if (rlast) r_bursts <= r_bursts + 8'd1;
      end
    end
  end

  // length of the W burst in progress: its AW accepted earlier, or presented now
  assign w_len = (w_bursts != aw_n) ? awlen_q[w_bursts[QB-1:0]] : awlen;
  assign r_len = arlen_q[r_bursts[QB-1:0]];

  // the slave: answers only accepted bursts, RLAST on beat ARLEN
  always_comb if (!rst) begin
    if (bvalid) assume (b_n != aw_n && b_n != w_bursts);
    if (rvalid) assume (r_bursts != ar_n);
    if (rvalid && RLAST_OK) assume (rlast == (r_beat == r_len));
  end

  // the master
  always_comb if (past && !rst) begin
    assert (8'(aw_n - b_n) <= 8'(MAX_OUT));
    assert (8'(ar_n - r_bursts) <= 8'(MAX_OUT));
    // W at most one burst ahead of AW, and only the burst whose AW is presented
    assert (8'(w_bursts - aw_n) <= 8'd1 || 8'(aw_n - w_bursts) <= 8'(MAX_OUT));
    if (w_bursts != aw_n && 8'(w_bursts - aw_n) <= 8'd1) assert (awvalid);
    if (wvalid) assert (8'(w_bursts - aw_n) != 8'd1);
    if (wvalid && w_bursts == aw_n) assert (awvalid);
    if (wvalid) assert (wlast == (w_beat == w_len));
    if (awvalid) assert ({1'b0, awaddr[11:0]} + ((13'(awlen) + 13'd1) << awsize) <= 13'h1000);
    if (arvalid) assert ({1'b0, araddr[11:0]} + ((13'(arlen) + 13'd1) << arsize) <= 13'h1000);
    if (awvalid) assert (awburst == 2'b01 && (8 << awsize) == DATA_W);
    if (arvalid) assert (arburst == 2'b01 && (8 << arsize) == DATA_W);
  end
  always_comb if (past && !rst) begin
    cover (awvalid && !awready);
    cover (w_hs && wlast && w_bursts == 8'd1);   // the second burst's last beat
    cover (b_hs && b_n == 8'd1);
    cover (8'(aw_n - b_n) == 8'(MAX_OUT));
    cover (arvalid && !arready);
    cover (r_hs && rlast && r_bursts == 8'd0);   // the first read burst's last beat
    if (COVER_R_MAX) cover (8'(ar_n - r_bursts) == 8'(MAX_OUT));
  end
endmodule

`default_nettype wire
