// SPDX-License-Identifier: Apache-2.0
// cfar_2d's cell under test, its neighbours and the 3x3 local-maximum test (stages 4..6 of
// its pipeline, docs/detect.md): shift registers of the previous PD+1 columns' cells in the
// CUT's row and in rows q-1 and q+1 (the CUT's column at PD-1, its Doppler neighbours at PD
// and PD-2, or the arriving column when PD = 1). The local maximum is the host's rule
// (host.cfar.local_peaks): no 8-neighbour greater than the cell; Doppler circular, a range
// neighbour outside the map does not exist (rm_ok4 / rp_ok4 low: taken as 0, never greater).
`default_nettype none

module cfar_peak #(
  parameter int PD = 10,          // GUARD_D + TRAIN_D
  parameter int POW_W = 34
) (
  input  wire logic                          clk,
  // stage 4: a tested row's column arrives (shift); its cells in rows q, q-1, q+1; rows
  // q-1 / q+1 exist
  input  wire logic                          ev4,
  input  wire logic [POW_W-1:0]              vcut4,
  input  wire logic [POW_W-1:0]              rm4,
  input  wire logic [POW_W-1:0]              rp4,
  input  wire logic                          rm_ok4,
  input  wire logic                          rp_ok4,
  // stage 5: the cell and its neighbours (r-1, d), (r+1, d) (0 outside the map), (r, d-1),
  // (r, d+1)
  output logic      [POW_W-1:0]              cut5,
  output logic      [POW_W-1:0]              nb_rm5,
  output logic      [POW_W-1:0]              nb_rp5,
  output logic      [POW_W-1:0]              nb_dm5,
  output logic      [POW_W-1:0]              nb_dp5,
  // stage 6: no neighbour greater than the cell
  output logic                               peak6
);

  // the shift registers, read at PD-2 (PD > 1), PD-1 and PD: rings (cfar_ring.sv)
  localparam logic [PD:0] USED = (PD > 1) ? (PD + 1)'(7) << ((PD > 1) ? PD - 2 : 0)
                                           : (PD + 1)'(3);
  logic [PD:0][POW_W-1:0] sr_c, sr_rm, sr_rp;
  cfar_ring #(.W(POW_W), .N(PD + 1), .USED(USED)) u_ring_c (
    .clk(clk), .en(ev4), .d(vcut4), .q(sr_c));
  cfar_ring #(.W(POW_W), .N(PD + 1), .USED(USED)) u_ring_rm (
    .clk(clk), .en(ev4), .d(rm4), .q(sr_rm));
  cfar_ring #(.W(POW_W), .N(PD + 1), .USED(USED)) u_ring_rp (
    .clk(clk), .en(ev4), .d(rp4), .q(sr_rp));

  // Doppler +1 neighbours (rows q, q-1, q+1): the arriving column when PD = 1
  logic [POW_W-1:0] nb_dp4, dg_mp4, dg_pp4;
  if (PD > 1) begin : g_dp_sr
    assign nb_dp4 = sr_c[PD-2];
    assign dg_mp4 = sr_rm[PD-2];
    assign dg_pp4 = sr_rp[PD-2];
  end else begin : g_dp_arriving
    assign nb_dp4 = vcut4;
    assign dg_mp4 = rm4;
    assign dg_pp4 = rp4;
  end

  // Stage 5: the cell, its neighbours, the diagonal neighbours
  logic [POW_W-1:0] dg5_q [4];   // (r-1, d-1), (r-1, d+1), (r+1, d-1), (r+1, d+1)
  always_ff @(posedge clk) begin
    cut5     <= sr_c[PD-1];
    nb_rm5   <= rm_ok4 ? sr_rm[PD-1] : '0;
    nb_rp5   <= rp_ok4 ? sr_rp[PD-1] : '0;
    nb_dm5   <= sr_c[PD];
    nb_dp5   <= nb_dp4;
    dg5_q[0] <= rm_ok4 ? sr_rm[PD] : '0;
    dg5_q[1] <= rm_ok4 ? dg_mp4 : '0;
    dg5_q[2] <= rp_ok4 ? sr_rp[PD] : '0;
    dg5_q[3] <= rp_ok4 ? dg_pp4 : '0;
  end

  // Stage 6: no neighbour greater than the cell
  always_ff @(posedge clk)
    peak6 <= (nb_rm5 <= cut5) && (nb_rp5 <= cut5) && (nb_dm5 <= cut5) && (nb_dp5 <= cut5) &&
             (dg5_q[0] <= cut5) && (dg5_q[1] <= cut5) && (dg5_q[2] <= cut5) &&
             (dg5_q[3] <= cut5);

endmodule

`default_nettype wire
