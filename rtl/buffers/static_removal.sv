// SPDX-License-Identifier: Apache-2.0
// Static-clutter removal between the corner turn and the Doppler FFT: each slow-time vector
// (one TX slot, one range bin, N_DOPPLER words of NUM_RX lanes) less its mean over the frame's
// chirps, per lane and per I/Q, the mean weighted by the Doppler window when WINDOW
// (model/static_removal.py; the float definition is model.reference.remove_static). Works
// behind either corner turn (corner_turn or frame_store_axi, both read whole Doppler vectors
// in either READ_ORDER).
//
// Why weighted: the Doppler FFT windows each vector with w (periodic Hann); subtracting
// c = sum(w x) / sum(w) removes a constant exactly and leaves the windowed zero-Doppler bin
// of every vector zero (sum w (x - c) = 0), whereas the plain mean of a moving target is its
// rectangular-window DFT at zero Doppler (-13 dB sidelobes), and subtracting it puts a residue
// 20-30 dB under the target into the zero-Doppler bin, which the CFAR detects.
//
// Structure: a ping-pong of two vectors. The writer stores vector v in one bank while
// accumulating sum(w[n] x[n]) over its first N_LOOPS words (per lane, I and Q, SUM_W-bit
// exact sums; w[n] the N_LOOPS-point window of fft_win_rom, the fft_window block's
// coefficients, or 1 without WINDOW) in a DSP-style multiply-accumulate: operand, product
// and sum registers; the reader streams the previous vector out of the other bank, less its
// mean, through two extra registers that match the two MACC stages. One word per clock per
// lane sustained: a bank is refilled from the clock after its last word was read, and a
// vector's mean is registered three clocks after its last word is written, before the
// reader's first word of it reaches the subtractor. Latency: one vector (N_DOPPLER words)
// plus 5 clocks.
//
// Why not the accumulate-while-writing-the-corner-turn scheme: that needs one accumulator per
// (TX, RX, range bin), two sets (the frame being read and the frame being written), inside
// both corner turns. For the full preset (4 TX x 16 RX, 256 range bins, 256 loops, 24-bit I
// and Q sums): 2 x 4 x 16 x 256 x 48 bits = 1.5 Mbit, against 2 x 256 x 16 x 32 bits =
// 256 Kbit here (six times less), and neither corner turn changes.
//
// Arithmetic (exact, model.static_removal.mean): sum s = sum(w x) over the vector's first
// N_LOOPS samples of one lane's I (or Q); divisor D = sum(w) = N_LOOPS * 2^15 with WINDOW
// (HANN[k] + HANN[k + 2048] = 65536 exactly, and every other generated window length sums
// so too: model.fft_rom.check_window_sums; model.static_removal.divisor, checked against
// the table in tests/test_static_removal.py), N_LOOPS without; mean
// m = floor((s * RECIP + 2^(SH-1)) / 2^SH) with SH = SUM_W + clog2(D) + 1,
// SUM_W = DATA_W + clog2(D) and RECIP = floor(2^SH / D) + 1. This is s / D rounded to
// nearest, ties away from zero, for every s in range (|s| <= 2^(DATA_W-1) D; the error of
// RECIP, |s| * (RECIP - 2^SH/D) / 2^SH < 1/(4 D), is below the 1/(2 D) that separates s / D
// from a rounding boundary, and it has the sign of s at a tie). With D a power of two
// (N_LOOPS a power of two) the product is a shift and an add (no multiplier); otherwise a
// SUM_W x RCP_W multiply per value, once per vector. Output word d < N_LOOPS:
// x - m saturated to DATA_W bits (sticky status_saturated); words d >= N_LOOPS (the zero fill
// of a frame with fewer loops than N_DOPPLER) pass unchanged.
//
// Run-time switch: `enable` is sampled with the first word of every frame (TUSER[0]) and
// holds for the whole frame; off, m = 0 and the words pass bit-identical with the same
// latency.
`default_nettype none

module static_removal #(
  // Receive lanes per word, 1..64.
  parameter int NUM_RX = 4,
  // Words per slow-time vector (in the pipeline: the loops, the Doppler FFT zero-fills
  // behind), 2..4096.
  parameter int N_DOPPLER = 256,
  // Chirp loops per frame whose mean is removed (the first N_LOOPS words of every vector),
  // 1..N_DOPPLER; any integer (the division is a reciprocal multiply, see above).
  parameter int N_LOOPS = N_DOPPLER,
  // Bits of I and of Q per lane, 8..32.
  parameter int DATA_W = 16,
  // 1: the mean weighted by the Doppler window (the pipeline's WINDOW: the fft_window
  // block's periodic Hann over N_LOOPS, fft_win_rom); 0: the plain mean.
  parameter bit WINDOW = 1'b1
) (
  input  wire logic                       clk,
  input  wire logic                       rst,
  // Run-time switch (register block), sampled with the first word of a frame
  input  wire logic                       enable,
  // Doppler vectors from the corner turn: TLAST on word N_DOPPLER-1 of every vector,
  // TUSER[0] on the first word of every frame
  input  wire logic [NUM_RX*2*DATA_W-1:0] s_axis_tdata,
  input  wire logic                       s_axis_tvalid,
  output logic                            s_axis_tready,
  input  wire logic                       s_axis_tlast,
  input  wire logic [0:0]                 s_axis_tuser,
  // The same vectors less their means, same TLAST/TUSER
  output logic      [NUM_RX*2*DATA_W-1:0] m_axis_tdata,
  output logic                            m_axis_tvalid,
  input  wire logic                       m_axis_tready,
  output logic                            m_axis_tlast,
  output logic      [0:0]                 m_axis_tuser,
  // Status (cleared only by rst), sticky
  output logic                            status_framing_error, // TLAST not on word N-1
  output logic                            status_saturated      // a difference saturated
);

  localparam int WORD_W = NUM_RX * 2 * DATA_W;
  localparam int NV     = 2 * NUM_RX;                 // values per word (I and Q of each lane)
  localparam int POS_W  = $clog2(N_DOPPLER);
  localparam int ROM_LOG2 = fft_rom_pkg::ROM_LOG2;
  localparam int COEF_W = fft_rom_pkg::COEF_W;        // signed weight (0..65536 windowed)
  // divisor = sum of the weights: N_LOOPS * 2^15 windowed (HANN[k] + HANN[k+2048] = 65536,
  // model.static_removal.divisor, checked in tests/test_static_removal.py), N_LOOPS plain
  localparam int DIV    = WINDOW ? (N_LOOPS << (fft_rom_pkg::COEF_FRAC - 1)) : N_LOOPS;
  localparam int LB     = $clog2(DIV);
  localparam int SUM_W  = DATA_W + LB;                // exact sum, |s| <= 2^(DATA_W-1) DIV
  localparam int SH     = SUM_W + LB + 1;
  localparam bit POW2   = (DIV == (1 << LB));
  localparam int RCP_W  = SH - LB + 2;                // bits of RECIP (unsigned)
  // (POW2: unused; SH reaches 71 for a windowed N_LOOPS = 4095, hence 128 bits)
  localparam logic [127:0] RECIP = POW2 ? 128'd1 : ((128'd1 << SH) / 128'(DIV)) + 128'd1;
  localparam int PROD_W = SUM_W + RCP_W + 1;

  // ---- parameter checks -----------------------------------------------------------------
  if (NUM_RX < 1 || NUM_RX > 64) begin : g_bad_num_rx
    $fatal(1, "%m: NUM_RX=%0d not in 1..64", NUM_RX);
  end
  if (N_DOPPLER < 2 || N_DOPPLER > 4096) begin : g_bad_n_doppler
    $fatal(1, "%m: N_DOPPLER=%0d not in 2..4096", N_DOPPLER);
  end
  if (N_LOOPS < 1 || N_LOOPS > N_DOPPLER) begin : g_bad_n_loops
    $fatal(1, "%m: N_LOOPS=%0d not in 1..N_DOPPLER (%0d)", N_LOOPS, N_DOPPLER);
  end
  // (WINDOW: fft_win_rom refuses an N_LOOPS it holds no window of)
  if (DATA_W < 8 || DATA_W > 32) begin : g_bad_data_w
    $fatal(1, "%m: DATA_W=%0d not in 8..32", DATA_W);
  end

  // ---- two banks of one vector, address {bank, word} -------------------------------------
  logic              ram_wr_en, ram_rd_en;
  logic [POS_W:0]    ram_wr_addr, ram_rd_addr;
  logic [WORD_W-1:0] ram_rd_data;

  buf_sdp_ram #(.WIDTH(WORD_W), .DEPTH(2 << POS_W)) u_ram (
    .clk, .wr_en(ram_wr_en), .wr_addr(ram_wr_addr), .wr_data(s_axis_tdata),
    .rd_en(ram_rd_en), .rd_addr(ram_rd_addr), .rd_data(ram_rd_data)
  );

  logic [1:0] full_q;        // bank holds a complete vector not yet fully read
  logic [1:0] sof_q;         // bank's vector starts a frame (TUSER[0] of its first word)
  logic [1:0] en_q;          // bank's vector has its mean removed (enable of its frame)

  // ---- write side: store and accumulate sum(w x) ----------------------------------------
  logic             wr_bank_q;
  logic [POS_W-1:0] wr_idx_q;
  logic             en_frame_q;                       // enable sampled at the frame start
  logic signed [DATA_W-1:0]         x_q [NV];         // multiplier operands (input registers)
  logic signed [COEF_W-1:0]         c_q;              //   (coefficient shared by the lanes)
  logic signed [DATA_W+COEF_W-1:0]  m_q [NV];         // products (product registers)
  logic signed [SUM_W-1:0]          acc_q [NV];       // running sums (output registers)
  logic             a_first_q, a_last_q, a_bank_q;    // word framing with x_q / c_q
  logic             m_first_q, m_last_q, m_bank_q;    //   with m_q
  logic             s_last_q, s_bank_q;               // acc_q holds a complete vector's sums
  logic signed [DATA_W-1:0] mean_q [2][NV];           // per bank

  logic beat, wr_first, wr_last, in_loops;
  assign s_axis_tready = !full_q[wr_bank_q];
  assign beat     = s_axis_tvalid && s_axis_tready;
  assign wr_first = (wr_idx_q == '0);
  assign wr_last  = (wr_idx_q == POS_W'(N_DOPPLER - 1));
  assign in_loops = ({1'b0, wr_idx_q} < (POS_W + 1)'(N_LOOPS));
  assign ram_wr_en   = beat;
  assign ram_wr_addr = {wr_bank_q, wr_idx_q};

  // the weight of word wr_idx_q: the N_LOOPS-point window (the fft_window block's
  // coefficients, rtl/fft/fft_win_rom.sv) windowed, 1 plain; 0 past the loops or without a beat
  logic [COEF_W-1:0] coef;
  if (WINDOW) begin : g_win
    fft_win_rom #(.N(N_LOOPS)) u_rom (.k(ROM_LOG2'(wr_idx_q)), .w_o(coef));
  end else begin : g_plain
    assign coef = COEF_W'(1);
  end

  // mean of a sum: floor((s * RECIP + 2^(SH-1)) / 2^SH)
  function automatic logic signed [DATA_W-1:0] mean_of(input logic signed [SUM_W-1:0] s);
    logic signed [PROD_W-1:0] p;
    if (POW2) begin   // RECIP = 2^(SH-LB) + 1: a shift and an add
      p = (PROD_W'(s) <<< (SH - LB)) + PROD_W'(s);
    end else begin
      p = PROD_W'(s) * $signed({1'b0, RCP_W'(RECIP)});
    end
    p = p + (PROD_W'(1) <<< (SH - 1));
    mean_of = DATA_W'(p >>> SH);
  endfunction

  // multiply-accumulate, DSP-friendly: operands, product and sum registered (acc_q is the
  // DSP's P register, cleared by the first product of a vector)
  always_ff @(posedge clk) begin
    for (int k = 0; k < NV; k++) begin
      x_q[k]   <= signed'(s_axis_tdata[k*DATA_W +: DATA_W]);
      m_q[k]   <= x_q[k] * c_q;
      acc_q[k] <= (m_first_q ? '0 : acc_q[k]) + SUM_W'(m_q[k]);
    end
    c_q       <= (beat && in_loops) ? signed'(coef) : '0;
    a_first_q <= beat && wr_first;
    a_last_q  <= beat && wr_last;
    a_bank_q  <= wr_bank_q;
    m_first_q <= a_first_q;
    m_last_q  <= a_last_q;
    m_bank_q  <= a_bank_q;
    s_last_q  <= m_last_q;
    s_bank_q  <= m_bank_q;
    if (s_last_q) for (int k = 0; k < NV; k++) mean_q[s_bank_q][k] <= mean_of(acc_q[k]);
    if (beat && wr_first) begin
      sof_q[wr_bank_q] <= s_axis_tuser[0];
      en_q[wr_bank_q]  <= s_axis_tuser[0] ? enable : en_frame_q;
    end
  end

  // ---- read side: stream the full bank out less its mean ----------------------------------
  logic             rd_bank_q;
  logic [POS_W-1:0] rd_idx_q;
  logic             can_issue, issue, rd_last;
  // word framing along the read pipeline: issue -> RAM data (stage 0) -> two registers
  // (stages 1, 2, matching the two MACC stages before a mean) -> subtractor
  logic [2:0]        p_last_q, p_user_q, p_sub_q, p_bank_q;
  logic [WORD_W-1:0] rd1_q, rd2_q;

  assign issue       = full_q[rd_bank_q] && can_issue;
  assign rd_last     = (rd_idx_q == POS_W'(N_DOPPLER - 1));
  assign ram_rd_en   = issue;
  assign ram_rd_addr = {rd_bank_q, rd_idx_q};

  always_ff @(posedge clk) begin
    p_last_q <= {p_last_q[1:0], rd_last};
    p_user_q <= {p_user_q[1:0], (rd_idx_q == '0) && sof_q[rd_bank_q]};
    p_sub_q  <= {p_sub_q[1:0], en_q[rd_bank_q] && ({1'b0, rd_idx_q} < (POS_W + 1)'(N_LOOPS))};
    p_bank_q <= {p_bank_q[1:0], rd_bank_q};
    rd1_q    <= ram_rd_data;
    rd2_q    <= rd1_q;
  end

  // x - m per value, saturated to DATA_W bits
  logic [WORD_W-1:0] diff;
  logic              sat;
  always_comb begin
    sat = 1'b0;
    for (int k = 0; k < NV; k++) begin
      logic signed [DATA_W:0] d;
      d = (DATA_W + 1)'(signed'(rd2_q[k*DATA_W +: DATA_W]))
        - (p_sub_q[2] ? (DATA_W + 1)'(mean_q[p_bank_q[2]][k]) : '0);
      if (d[DATA_W] != d[DATA_W-1]) begin
        sat = 1'b1;
        diff[k*DATA_W +: DATA_W] = d[DATA_W] ? {1'b1, {(DATA_W-1){1'b0}}}
                                             : {1'b0, {(DATA_W-1){1'b1}}};
      end else begin
        diff[k*DATA_W +: DATA_W] = d[DATA_W-1:0];
      end
    end
  end

  logic [2:0] push_q;    // bit 2: a read issued 3 clocks ago, its word enters the FIFO now
  logic framing_q, sat_q;
  always_ff @(posedge clk) begin
    if (rst) begin
      full_q     <= '0;
      wr_bank_q  <= 1'b0;
      wr_idx_q   <= '0;
      en_frame_q <= 1'b0;
      rd_bank_q  <= 1'b0;
      rd_idx_q   <= '0;
      push_q     <= '0;
      framing_q  <= 1'b0;
      sat_q      <= 1'b0;
    end else begin
      push_q    <= {push_q[1:0], issue};
      if (beat) begin
        wr_idx_q <= wr_last ? '0 : wr_idx_q + 1'b1;
        if (wr_first && s_axis_tuser[0]) en_frame_q <= enable;
        if (s_axis_tlast != wr_last) framing_q <= 1'b1;
        if (wr_last) wr_bank_q <= !wr_bank_q;
      end
      if (issue) begin
        rd_idx_q <= rd_last ? '0 : rd_idx_q + 1'b1;
        if (rd_last) rd_bank_q <= !rd_bank_q;
      end
      // a bank fills on its last write and empties on its last read (never both: the
      // writer only writes a bank that is not full, the reader only reads a full one)
      for (int b = 0; b < 2; b++) begin
        if (beat && wr_last && wr_bank_q == 1'(b)) full_q[b] <= 1'b1;
        if (issue && rd_last && rd_bank_q == 1'(b)) full_q[b] <= 1'b0;
      end
      if (push_q[2] && sat) sat_q <= 1'b1;
    end
  end

  // ---- output ---------------------------------------------------------------------------
  logic [WORD_W+1:0] fifo_tdata;
  buf_out_fifo #(.WIDTH(WORD_W + 2), .DEPTH(8), .LATENCY(3)) u_out (
    .clk, .rst, .can_issue, .issue, .in_data({p_user_q[2], p_last_q[2], diff}),
    .m_axis_tdata(fifo_tdata), .m_axis_tvalid, .m_axis_tready
  );
  assign m_axis_tdata    = fifo_tdata[WORD_W-1:0];
  assign m_axis_tlast    = fifo_tdata[WORD_W];
  assign m_axis_tuser[0] = fifo_tdata[WORD_W+1];

  assign status_framing_error = framing_q;
  assign status_saturated     = sat_q;

`ifndef SYNTHESIS
  axis_checker #(.PAYLOAD_W(WORD_W + 2), .ASSUME(1'b1)) u_chk_s_axis (
    .clk, .rst, .tvalid(s_axis_tvalid), .tready(s_axis_tready),
    .payload({s_axis_tuser, s_axis_tlast, s_axis_tdata}));
  axis_checker #(.PAYLOAD_W(WORD_W + 2)) u_chk_m_axis (
    .clk, .rst, .tvalid(m_axis_tvalid), .tready(m_axis_tready),
    .payload({m_axis_tuser, m_axis_tlast, m_axis_tdata}));
  // block invariant: the mean of a bank is registered before its first word is subtracted
  always_ff @(posedge clk) begin
    if (!rst) assert (!(push_q[2] && s_last_q && p_sub_q[2] && s_bank_q == p_bank_q[2]))
      else $error("%m: a vector's first word reached the subtractor before its mean");
  end
`endif

endmodule

`default_nettype wire
