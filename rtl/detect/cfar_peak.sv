// SPDX-License-Identifier: Apache-2.0
// cfar_2d's cell under test, its neighbours and the 3x3 local-maximum test (stages 4..6 of
// its pipeline, docs/detect.md): shift registers on ev4 of the last PD+2 columns' cells in the
// CUT's row and in rows q-1 and q+1. A cell at stage 5 is one whose column shifted in at the
// clock edge that began stage 5 (its ev4), so its own column then sits at PD, its Doppler
// neighbours at PD-1 (d+1) and PD+1 (d-1): the stage-5 outputs are those positions
// themselves, not copies of them (the positions hold until the next ev4, after stage 5). The
// local maximum is the host's rule (host.cfar.local_peaks): no 8-neighbour greater than the
// cell; Doppler circular, a range neighbour outside the map does not exist (rm_ok4 / rp_ok4
// low: taken as 0, never greater).
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
  // (r, d+1), valid for a cell whose ev4 began stage 5
  output logic      [POW_W-1:0]              cut5,
  output logic      [POW_W-1:0]              nb_rm5,
  output logic      [POW_W-1:0]              nb_rp5,
  output logic      [POW_W-1:0]              nb_dm5,
  output logic      [POW_W-1:0]              nb_dp5,
  // stage 6: no neighbour greater than the cell
  output logic                               peak6
);

  // the shift registers, read at PD-1, PD and PD+1: rings (cfar_ring.sv)
  localparam logic [PD+1:0] USED = (PD + 2)'(7) << (PD - 1);
  logic [PD+1:0][POW_W-1:0] sr_c, sr_rm, sr_rp;
  cfar_ring #(.W(POW_W), .N(PD + 2), .USED(USED)) u_ring_c (
    .clk(clk), .en(ev4), .d(vcut4), .q(sr_c));
  cfar_ring #(.W(POW_W), .N(PD + 2), .USED(USED)) u_ring_rm (
    .clk(clk), .en(ev4), .d(rm4), .q(sr_rm));
  cfar_ring #(.W(POW_W), .N(PD + 2), .USED(USED)) u_ring_rp (
    .clk(clk), .en(ev4), .d(rp4), .q(sr_rp));

  // Stage 5: the cell, its neighbours (rows q-1 / q+1 masked by their existence)
  logic rm_ok5_q, rp_ok5_q;
  always_ff @(posedge clk) begin
    rm_ok5_q <= rm_ok4;
    rp_ok5_q <= rp_ok4;
  end
  assign cut5   = sr_c[PD];
  assign nb_dp5 = sr_c[PD-1];
  assign nb_dm5 = sr_c[PD+1];
  assign nb_rm5 = rm_ok5_q ? sr_rm[PD] : '0;
  assign nb_rp5 = rp_ok5_q ? sr_rp[PD] : '0;

  // Stage 6: no neighbour greater than the cell (a row outside the map: no neighbour there)
  always_ff @(posedge clk)
    peak6 <= (nb_dm5 <= cut5) && (nb_dp5 <= cut5) &&
             (!rm_ok5_q || ((sr_rm[PD] <= cut5) && (sr_rm[PD-1] <= cut5) &&
                            (sr_rm[PD+1] <= cut5))) &&
             (!rp_ok5_q || ((sr_rp[PD] <= cut5) && (sr_rp[PD-1] <= cut5) &&
                            (sr_rp[PD+1] <= cut5)));

endmodule

`default_nettype wire
