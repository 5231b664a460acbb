// SPDX-License-Identifier: Apache-2.0
// ADC-side chirp ping-pong buffer: the ADC writes one chirp bank while the range FFT drains
// the other; only complete, correctly framed chirps are forwarded, so chirps never mix.
//
// Overflow policy (ADC_BACKPRESSURE=0, a real ADC cannot stall): a chirp whose first sample
// finds no free bank is discarded whole (every sample of it is dropped and counted, the chirp
// is counted, status_overflow is set) and the next chirp that is forwarded carries
// m_axis_tuser[1] = 1 (discontinuity) on its first sample. Framing policy: a chirp whose TLAST
// is not on sample N_RANGE-1 is discarded the same way (early TLAST: the next sample starts a
// chirp; missing TLAST: samples are dropped up to and including the next TLAST).
`default_nettype none

module chirp_pingpong #(
  // Receive lanes per word (one {Q,I} sample each), 1..64.
  parameter int NUM_RX = 4,
  // Samples per chirp (range FFT length), 2..65536.
  parameter int N_RANGE = 64,
  // Bits of I and of Q per lane, 8..32.
  parameter int DATA_W = 16,
  // 0: s_axis_tready is always 1 and a chirp that finds no free bank is dropped;
  // 1: s_axis_tready deasserts while the write bank is busy (nothing is dropped).
  parameter bit ADC_BACKPRESSURE = 1'b0
) (
  input  wire logic                       clk,
  input  wire logic                       rst,
  // ADC samples: TLAST on the last sample of each chirp, TUSER[0] on the first of a frame
  input  wire logic [NUM_RX*2*DATA_W-1:0] s_axis_tdata,
  input  wire logic                       s_axis_tvalid,
  output logic                            s_axis_tready,
  input  wire logic                       s_axis_tlast,
  input  wire logic [0:0]                 s_axis_tuser,
  // Whole chirps to the range FFT: TLAST on sample N_RANGE-1; on the first sample
  // TUSER[0] = frame start (copied from the input), TUSER[1] = chirps were discarded before
  output logic      [NUM_RX*2*DATA_W-1:0] m_axis_tdata,
  output logic                            m_axis_tvalid,
  input  wire logic                       m_axis_tready,
  output logic                            m_axis_tlast,
  output logic      [1:0]                 m_axis_tuser,
  // Status (cleared only by rst)
  output logic                            status_overflow,      // sticky: a chirp was dropped
  output logic                            status_framing_error, // sticky: TLAST misplaced
  output logic      [31:0]                drop_count,           // samples dropped by overflow
  output logic      [31:0]                chirps_dropped,       // chirps dropped by overflow
  output logic      [31:0]                framing_error_count,  // misplaced/missing TLASTs
  output logic      [31:0]                chirps_out            // chirps forwarded
);

  localparam int WORD_W = NUM_RX * 2 * DATA_W;
  localparam int POS_W  = $clog2(N_RANGE);

  // Parameter checks: stop elaboration on illegal values.
  if (NUM_RX < 1 || NUM_RX > 64) begin : g_bad_num_rx
    $fatal(1, "%m: NUM_RX=%0d not in 1..64", NUM_RX);
  end
  if (N_RANGE < 2 || N_RANGE > 65536) begin : g_bad_n_range
    $fatal(1, "%m: N_RANGE=%0d not in 2..65536", N_RANGE);
  end
  if (DATA_W < 8 || DATA_W > 32) begin : g_bad_data_w
    $fatal(1, "%m: DATA_W=%0d not in 8..32", DATA_W);
  end

  // ---------------------------------------------------------------------------------------
  // Two banks of 2^POS_W words, address {bank, sample}
  logic              ram_wr_en, ram_rd_en;
  logic [POS_W:0]    ram_wr_addr, ram_rd_addr;
  logic [WORD_W-1:0] ram_rd_data;

  buf_sdp_ram #(.WIDTH(WORD_W), .DEPTH(2 << POS_W)) u_ram (
    .clk     (clk),
    .wr_en   (ram_wr_en),
    .wr_addr (ram_wr_addr),
    .wr_data (s_axis_tdata),
    .rd_en   (ram_rd_en),
    .rd_addr (ram_rd_addr),
    .rd_data (ram_rd_data)
  );

  logic [1:0] full_q;            // bank holds a complete chirp not yet fully read
  logic [1:0] sof_q, gap_q;      // per-bank first-sample flags

  // ---------------------------------------------------------------------------------------
  // Write side
  logic             wr_bank_q;
  logic [POS_W-1:0] pos_q;       // sample index within the current chirp
  logic             discard_q;   // current chirp is being dropped (overflow)
  logic             skip_q;      // resynchronising: dropping up to the next TLAST
  logic             chirp_sof_q; // current chirp's first sample had TUSER[0]
  logic             gap_pend_q;  // a chirp was discarded since the last forwarded one
  logic             ovf_q, framing_q;
  logic [31:0]      drop_cnt_q, chirp_drop_q, framing_cnt_q, chirps_out_q;

  logic beat, first, last_pos, ovf_drop, keep, tlast_err, commit;

  assign s_axis_tready = ADC_BACKPRESSURE ? (skip_q || !full_q[wr_bank_q]) : 1'b1;
  assign beat      = s_axis_tvalid && s_axis_tready;
  assign first     = (pos_q == '0);
  assign last_pos  = (pos_q == POS_W'(N_RANGE - 1));
  // the drop decision is taken on the chirp's first sample and kept for the whole chirp
  assign ovf_drop  = first ? full_q[wr_bank_q] : discard_q;
  assign keep      = !skip_q && !ovf_drop;
  assign tlast_err = !skip_q && (s_axis_tlast != last_pos);
  assign commit    = beat && keep && last_pos && s_axis_tlast;

  assign ram_wr_en   = beat && keep;
  assign ram_wr_addr = {wr_bank_q, pos_q};

  // ---------------------------------------------------------------------------------------
  // Read side
  logic             rd_bank_q;
  logic [POS_W-1:0] rd_idx_q;
  logic             can_issue, issue, rd_last;
  logic             p_last_q;
  logic [1:0]       p_user_q;

  assign issue       = full_q[rd_bank_q] && can_issue;
  assign rd_last     = (rd_idx_q == POS_W'(N_RANGE - 1));
  assign ram_rd_en   = issue;
  assign ram_rd_addr = {rd_bank_q, rd_idx_q};

  always_ff @(posedge clk) begin
    p_last_q <= rd_last;
    p_user_q <= (rd_idx_q == '0) ? {gap_q[rd_bank_q], sof_q[rd_bank_q]} : 2'b00;
    if (commit) begin
      sof_q[wr_bank_q] <= chirp_sof_q;
      gap_q[wr_bank_q] <= gap_pend_q;
    end
  end

  always_ff @(posedge clk) begin
    if (rst) begin
      full_q        <= '0;
      wr_bank_q     <= 1'b0;
      pos_q         <= '0;
      discard_q     <= 1'b0;
      skip_q        <= 1'b0;
      chirp_sof_q   <= 1'b0;
      gap_pend_q    <= 1'b0;
      ovf_q         <= 1'b0;
      framing_q     <= 1'b0;
      drop_cnt_q    <= '0;
      chirp_drop_q  <= '0;
      framing_cnt_q <= '0;
      chirps_out_q  <= '0;
      rd_bank_q     <= 1'b0;
      rd_idx_q      <= '0;
    end else begin
      if (beat) begin
        if (!skip_q && ovf_drop && drop_cnt_q != '1) drop_cnt_q <= drop_cnt_q + 1'b1;
        if (tlast_err) begin
          framing_q <= 1'b1;
          if (framing_cnt_q != '1) framing_cnt_q <= framing_cnt_q + 1'b1;
        end
        if (first) begin
          discard_q   <= full_q[wr_bank_q];
          chirp_sof_q <= s_axis_tuser[0];
        end
        if (skip_q) begin
          // resynchronising after a missing TLAST: the TLAST ends the skipped run
          if (s_axis_tlast) begin
            skip_q <= 1'b0;
            pos_q  <= '0;
          end
        end else if (s_axis_tlast || last_pos) begin
          // end of a chirp, good or bad
          pos_q <= '0;
          if (!s_axis_tlast) skip_q <= 1'b1;              // missing TLAST
          if (commit) begin
            full_q[wr_bank_q] <= 1'b1;
            wr_bank_q         <= !wr_bank_q;
            gap_pend_q        <= 1'b0;
          end else begin
            gap_pend_q <= 1'b1;
            if (ovf_drop) begin
              ovf_q <= 1'b1;
              if (chirp_drop_q != '1) chirp_drop_q <= chirp_drop_q + 1'b1;
            end
          end
        end else begin
          pos_q <= pos_q + 1'b1;
        end
      end
      if (issue) begin
        if (rd_last) begin
          rd_idx_q          <= '0;
          full_q[rd_bank_q] <= 1'b0;
          rd_bank_q         <= !rd_bank_q;
          chirps_out_q      <= chirps_out_q + 1'b1;
        end else begin
          rd_idx_q <= rd_idx_q + 1'b1;
        end
      end
    end
  end

  // ---------------------------------------------------------------------------------------
  // Output
  logic [WORD_W+2:0] fifo_tdata;

  buf_out_fifo #(.WIDTH(WORD_W + 3), .DEPTH(4)) u_out (
    .clk           (clk),
    .rst           (rst),
    .can_issue     (can_issue),
    .issue         (issue),
    .in_data       ({p_user_q, p_last_q, ram_rd_data}),
    .m_axis_tdata  (fifo_tdata),
    .m_axis_tvalid (m_axis_tvalid),
    .m_axis_tready (m_axis_tready)
  );
  assign m_axis_tdata = fifo_tdata[WORD_W-1:0];
  assign m_axis_tlast = fifo_tdata[WORD_W];
  assign m_axis_tuser = fifo_tdata[WORD_W+2:WORD_W+1];

  assign status_overflow      = ovf_q;
  assign status_framing_error = framing_q;
  assign drop_count           = drop_cnt_q;
  assign chirps_dropped       = chirp_drop_q;
  assign framing_error_count  = framing_cnt_q;
  assign chirps_out           = chirps_out_q;

  // AXI4-Stream protocol on every port (rtl/common/axis_checker.sv)
  axis_checker #(.PAYLOAD_W(NUM_RX*2*DATA_W + 2), .ASSUME(1'b1)) u_chk_s_axis (
    .clk, .rst, .tvalid(s_axis_tvalid), .tready(s_axis_tready),
    .payload({s_axis_tuser, s_axis_tlast, s_axis_tdata}));
  axis_checker #(.PAYLOAD_W(NUM_RX*2*DATA_W + 3)) u_chk_m_axis (
    .clk, .rst, .tvalid(m_axis_tvalid), .tready(m_axis_tready),
    .payload({m_axis_tuser, m_axis_tlast, m_axis_tdata}));

`ifdef FORMAL
  // Formal properties (formal/chirp_pingpong.sby). Chirps never mix: a bank holding an
  // unread chirp is never written, only a full bank is read, banks are filled and drained in
  // turn, a committed chirp is N_RANGE kept samples written at positions 0..N_RANGE-1;
  // chirps committed - chirps read == full banks; with ADC_BACKPRESSURE nothing is dropped;
  // status flags sticky. bmc adds the output framing (TLAST every N_RANGE words, TUSER only
  // on a chirp's first word), which sits in the output FIFO.
  logic                f_past = 1'b0;
  logic [N_RANGE-1:0]  f_wmask;        // positions written of the chirp being written
  logic [7:0]          f_commits = '0;
  logic [POS_W-1:0]    f_out_pos = '0;
  initial assume (rst);
  always_ff @(posedge clk) begin
    f_past <= 1'b1;
    if (rst) begin
      f_wmask   <= '0;
      f_commits <= '0;
      f_out_pos <= '0;
    end else begin
      if (ram_wr_en) f_wmask <= (first ? '0 : f_wmask) | (N_RANGE'(1) << pos_q);
      else if (beat && first) f_wmask <= '0;
      if (commit) f_commits <= f_commits + 8'd1;
      if (m_axis_tvalid && m_axis_tready) f_out_pos <= m_axis_tlast ? '0 : f_out_pos + 1'b1;
    end
  end
  always_comb if (f_past && !rst) begin
    assume (chirps_out_q != '1);
    assert ({1'b0, pos_q} <= (POS_W+1)'(N_RANGE - 1));
    if (ram_wr_en) assert (!full_q[wr_bank_q]);
    if (!skip_q && !discard_q && pos_q != '0) assert (!full_q[wr_bank_q]);
    if (issue) assert (full_q[rd_bank_q]);
    if (wr_bank_q == rd_bank_q) assert (full_q[0] == full_q[1]);
    else assert (full_q[rd_bank_q] && !full_q[wr_bank_q]);
    if (!full_q[rd_bank_q]) assert (rd_idx_q == '0);
    if (commit) assert ((f_wmask | (N_RANGE'(1) << pos_q)) == '1);
    // kept samples of the open chirp are exactly the positions below pos_q
    if (!skip_q && !discard_q && pos_q != '0)
      assert (f_wmask == (N_RANGE'(1) << pos_q) - 1'b1);
    assert (8'(f_commits - 8'(chirps_out_q)) == 8'(full_q[0]) + 8'(full_q[1]));
    if (ADC_BACKPRESSURE) begin
      if (beat) assert (keep || skip_q);
      assert (drop_cnt_q == '0 && !ovf_q);
      if (pos_q != '0 && !skip_q) assert (!discard_q);
    end
`ifdef F_OUTPUT_FRAMING
    if (m_axis_tvalid) begin
      assert (m_axis_tlast == (f_out_pos == POS_W'(N_RANGE - 1)));
      if (f_out_pos != '0) assert (m_axis_tuser == 2'b00);
    end
`endif
  end
  always_ff @(posedge clk) if (f_past && !$past(rst) && !rst) begin
    if ($past(ovf_q)) assert (ovf_q);
    if ($past(framing_q)) assert (framing_q);
  end
  always_comb if (f_past && !rst) begin
    cover (full_q == 2'b11);
    cover (m_axis_tvalid && m_axis_tlast && !m_axis_tready);
    cover (chirps_out_q == 32'd1 && framing_q);
    cover (chirps_out_q == 32'd1 && (ovf_q || ADC_BACKPRESSURE));
  end
`endif

`ifdef FORMAL
  // (the FORMAL block above states this property for the proof)
`elsif SYNTHESIS
`else
  // block invariant: with ADC_BACKPRESSURE nothing is ever dropped
  always_ff @(posedge clk) begin
    if (!rst && ADC_BACKPRESSURE && beat) assert (keep || skip_q)
      else $error("chirp_pingpong: sample dropped with ADC_BACKPRESSURE=1");
  end
`endif

endmodule

`default_nettype wire
