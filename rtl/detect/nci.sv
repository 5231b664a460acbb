// SPDX-License-Identifier: Apache-2.0
// Non-coherent integration: sum of |x|^2 over the NUM_TX x NUM_RX virtual channels of every
// (range, Doppler) cell of the Doppler-FFT output, one input word per clock, exact (no
// rounding, no saturation).
//
// Input order (docs/design.md 3.4, mode 1): for range bin r, for TX t, for Doppler bin d: one word of
// NUM_RX {Q,I} lanes (the corner turn reads (r, t) in mode 1; with NUM_TX = 1 this is the
// mode-0 order). The partial sums of TX 0..NUM_TX-2 wait in an N_DOPPLER-deep accumulator
// RAM; the word of the last TX completes the cell. Output order: for r, for d.
// Width: |x|^2 <= 2 * 2^(2*DATA_W-2) = 2^(2*DATA_W-1) per lane, so the sum of NUM_TX*NUM_RX
// of them needs POW_W = 2*DATA_W + clog2(NUM_TX*NUM_RX) bits (docs/detect.md).
// Frame boundaries come from counting words after reset; s_axis_tlast is only checked (last
// word of every Doppler vector) and a mismatch raises the sticky framing error flag.
`default_nettype none

module nci #(
  // TDM transmit slots, 1..16.
  parameter int NUM_TX = 1,
  // Receive lanes per input word, 1..64.
  parameter int NUM_RX = 4,
  // Range bins per frame, power of two, 2..4096.
  parameter int N_RANGE = 64,
  // Doppler bins per vector, power of two, 2..4096.
  parameter int N_DOPPLER = 256,
  // Bits of I and of Q per lane (two's complement), 2..32.
  parameter int DATA_W = 16,
  // Integrated power width (derived, do not override).
  parameter int POW_W = 2 * DATA_W + $clog2(NUM_TX * NUM_RX),
  // Output tdata width: POW_W rounded up to whole bytes (derived, do not override).
  parameter int OUT_W = ((POW_W + 7) / 8) * 8
) (
  input  wire logic                              clk,
  input  wire logic                              rst,
  // Doppler-FFT output, order (r, t, d); TLAST on Doppler bin N_DOPPLER-1 (checked only)
  input  wire logic [NUM_RX*2*DATA_W-1:0]        s_axis_tdata,
  input  wire logic                              s_axis_tvalid,
  output logic                                   s_axis_tready,
  input  wire logic                              s_axis_tlast,
  // Power map, order (r, d): tdata = integrated power (zero-extended to OUT_W),
  // tuser = {r, d}, TLAST on Doppler bin N_DOPPLER-1 of every range row
  output logic      [OUT_W-1:0]                  m_axis_tdata,
  output logic                                   m_axis_tvalid,
  input  wire logic                              m_axis_tready,
  output logic                                   m_axis_tlast,
  output logic      [$clog2(N_RANGE)+$clog2(N_DOPPLER)-1:0] m_axis_tuser,
  // Status (cleared only by rst)
  output logic                                   status_framing_error, // sticky: TLAST misplaced
  output logic      [31:0]                       frame_count           // input frames completed
);

  localparam int BR  = $clog2(N_RANGE);
  localparam int BD  = $clog2(N_DOPPLER);
  localparam int BT  = (NUM_TX > 1) ? $clog2(NUM_TX) : 1;
  localparam int LP_W = 2 * DATA_W;                     // one lane's |x|^2 (unsigned)

  // Parameter checks: stop elaboration on illegal values.
  if (NUM_TX < 1 || NUM_TX > 16) begin : g_bad_num_tx
    $fatal(1, "%m: NUM_TX=%0d not in 1..16", NUM_TX);
  end
  if (NUM_RX < 1 || NUM_RX > 64) begin : g_bad_num_rx
    $fatal(1, "%m: NUM_RX=%0d not in 1..64", NUM_RX);
  end
  if (N_RANGE < 2 || N_RANGE > 4096 || (1 << BR) != N_RANGE) begin : g_bad_n_range
    $fatal(1, "%m: N_RANGE=%0d must be a power of two in 2..4096", N_RANGE);
  end
  if (N_DOPPLER < 2 || N_DOPPLER > 4096 || (1 << BD) != N_DOPPLER) begin : g_bad_n_doppler
    $fatal(1, "%m: N_DOPPLER=%0d must be a power of two in 2..4096", N_DOPPLER);
  end
  if (DATA_W < 2 || DATA_W > 32) begin : g_bad_data_w
    $fatal(1, "%m: DATA_W=%0d not in 2..32", DATA_W);
  end
  if (POW_W != 2 * DATA_W + $clog2(NUM_TX * NUM_RX) || OUT_W < POW_W) begin : g_bad_pow_w
    $fatal(1, "%m: POW_W/OUT_W are derived, do not override");
  end

  // ---------------------------------------------------------------------------------------
  // Input counters (frame position from counting words after reset)
  logic [BD-1:0] d_q;
  logic [BT-1:0] t_q;
  logic [BR-1:0] r_q;
  logic          framing_q;
  logic [31:0]   frame_cnt_q;
  logic          beat, last_tx, can_issue;

  assign s_axis_tready = can_issue;
  assign beat          = s_axis_tvalid && s_axis_tready;
  assign last_tx       = (NUM_TX == 1) || (t_q == BT'(NUM_TX - 1));

  // ---------------------------------------------------------------------------------------
  // Pipeline, k clocks after the beat (stage k): 1 the word registered (multiplier inputs),
  // 2 the squares I^2, Q^2 of every lane (products), 3 the lanes' I^2 + Q^2 summed in pairs,
  // 4 the word's power (the rest of the adder tree) plus the partial sum of TX 0..t-1 (the
  // accumulator RAM read is issued at stage 3): the cell's sum, to the output FIFO and the RAM
  localparam int LAT = 4;
  localparam int NP  = (NUM_RX + 1) / 2;                // lane pairs
  logic [LAT:1]         v_q;                            // a beat is in stage k (reset)
  logic [LAT:1]         first_q, last_q;
  logic [BD-1:0]        dd_q [LAT:1];
  logic [BR-1:0]        rr_q [LAT:1];
  logic [NUM_RX*2*DATA_W-1:0] x1_q;
  logic [LP_W-1:0]      sq2_q [2*NUM_RX];
  logic [POW_W-1:0]     t3_q [64], s1_pow_q, acc_rd, s1_sum;

  always_ff @(posedge clk) begin
    x1_q <= s_axis_tdata;
    // squares of the sign-extended lanes (>= 0)
    for (int c = 0; c < 2 * NUM_RX; c++) begin
      logic signed [LP_W-1:0] x_s, x2;
      x_s = LP_W'(signed'(x1_q[c*DATA_W +: DATA_W]));
      x2  = x_s * x_s;
      sq2_q[c] <= unsigned'(x2);
    end
    for (int k = 0; k < 64; k++) begin
      t3_q[k] <= '0;
      if (k < NP) begin
        t3_q[k] <= POW_W'(sq2_q[(4 * k) % (2 * NUM_RX)])
                 + POW_W'(sq2_q[(4 * k + 1) % (2 * NUM_RX)]);
        if (2 * k + 1 < NUM_RX)
          t3_q[k] <= POW_W'(sq2_q[(4 * k) % (2 * NUM_RX)])
                   + POW_W'(sq2_q[(4 * k + 1) % (2 * NUM_RX)])
                   + POW_W'(sq2_q[(4 * k + 2) % (2 * NUM_RX)])
                   + POW_W'(sq2_q[(4 * k + 3) % (2 * NUM_RX)]);
      end
    end
  end

  // stage 4: the pair sums added up as a tree (terms beyond NP are constant zero)
  always_ff @(posedge clk) begin
    logic [POW_W-1:0] t [64];
    for (int k = 0; k < 64; k++) t[k] = t3_q[k];
    for (int w = 32; w >= 1; w = w / 2)
      for (int k = 0; k < w; k++) t[k] = t[2 * k] + t[2 * k + 1];
    s1_pow_q <= t[0];
  end

  // ---------------------------------------------------------------------------------------
  // Stage 4: add the partial sum of TX 0..t-1 (accumulator RAM, read issued at stage 3; the
  // same cell's next TX word is read N_DOPPLER >= 2 beats later, after this write)
  if (NUM_TX > 1) begin : g_acc
    buf_sdp_ram #(.WIDTH(POW_W), .DEPTH(N_DOPPLER)) u_acc (
      .clk     (clk),
      .wr_en   (v_q[LAT] && !last_q[LAT]),
      .wr_addr (dd_q[LAT]),
      .wr_data (s1_sum),
      .rd_en   (v_q[LAT-1]),
      .rd_addr (dd_q[LAT-1]),
      .rd_data (acc_rd)
    );
  end else begin : g_no_acc
    assign acc_rd = '0;
    logic unused_ok;
    assign unused_ok = ^{v_q[LAT], last_q[LAT]};
  end

  assign s1_sum = s1_pow_q + (first_q[LAT] ? '0 : acc_rd);

  always_ff @(posedge clk) begin
    first_q[1] <= (t_q == '0);
    last_q[1]  <= last_tx;
    dd_q[1]    <= d_q;
    rr_q[1]    <= r_q;
    for (int k = 2; k <= LAT; k++) begin
      first_q[k] <= first_q[k-1];
      last_q[k]  <= last_q[k-1];
      dd_q[k]    <= dd_q[k-1];
      rr_q[k]    <= rr_q[k-1];
    end
  end

  always_ff @(posedge clk) begin
    if (rst) begin
      v_q         <= '0;
      d_q         <= '0;
      t_q         <= '0;
      r_q         <= '0;
      framing_q   <= 1'b0;
      frame_cnt_q <= '0;
    end else begin
      v_q <= {v_q[LAT-1:1], beat};
      if (beat) begin
        if (s_axis_tlast != (d_q == '1)) framing_q <= 1'b1;
        d_q <= d_q + 1'b1;
        if (d_q == '1) begin
          t_q <= last_tx ? '0 : t_q + 1'b1;
          if (last_tx) begin
            r_q <= r_q + 1'b1;
            if (r_q == '1) frame_cnt_q <= frame_cnt_q + 1'b1;
          end
        end
      end
    end
  end

  // ---------------------------------------------------------------------------------------
  // Output: a cell leaves when the word of its last TX has been added
  localparam int FW = POW_W + BR + BD + 1;
  logic [FW-1:0] fifo_tdata;

  buf_out_fifo #(.WIDTH(FW), .DEPTH(8), .LATENCY(LAT)) u_out (
    .clk           (clk),
    .rst           (rst),
    .can_issue     (can_issue),
    .issue         (beat && last_tx),
    .in_data       ({(dd_q[LAT] == '1), rr_q[LAT], dd_q[LAT], s1_sum}),
    .m_axis_tdata  (fifo_tdata),
    .m_axis_tvalid (m_axis_tvalid),
    .m_axis_tready (m_axis_tready)
  );
  assign m_axis_tdata = OUT_W'(fifo_tdata[POW_W-1:0]);
  assign m_axis_tuser = fifo_tdata[POW_W +: BR + BD];
  assign m_axis_tlast = fifo_tdata[FW-1];

  assign status_framing_error = framing_q;
  assign frame_count          = frame_cnt_q;

  // AXI4-Stream protocol on every port (rtl/common/axis_checker.sv)
  axis_checker #(.PAYLOAD_W(NUM_RX*2*DATA_W + 1), .ASSUME(1'b1)) u_chk_s_axis (
    .clk, .rst, .tvalid(s_axis_tvalid), .tready(s_axis_tready),
    .payload({s_axis_tlast, s_axis_tdata}));
  axis_checker #(.PAYLOAD_W(OUT_W + 1 + $clog2(N_RANGE) + $clog2(N_DOPPLER))) u_chk_m_axis (
    .clk, .rst, .tvalid(m_axis_tvalid), .tready(m_axis_tready),
    .payload({m_axis_tuser, m_axis_tlast, m_axis_tdata}));

endmodule

`default_nettype wire
