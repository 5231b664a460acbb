# Open 77 GHz FMCW TDM-MIMO radar array processor.
#   make demo   run the Table I scene end to end and write figures to out/
#   make test   the whole regression (Python model/host/gnn tests + every RTL testbench)
# Both create .venv and install the pinned toolchain on first use.

PYTHON ?= $(shell command -v python3.11 || command -v python3)
VENV   := .venv
STAMP  := $(VENV)/.installed
RUN    := tools/venv-run
JOBS   ?= auto
OUT    ?= out

.PHONY: all setup demo test test-python sim lint gen regs bench bench-rtl soak gnn-dataset gnn-train \
        gnn-eval clean help view view-records bench-view test-detect-long test-full test-full-detect \
        test-process-rtl formal coverage mutate mutate-ci curves bench-ray bench-openradar
all: test

help:
	@echo "make setup           create .venv and install the pinned toolchain (idempotent)"
	@echo "make demo            Table I scene end to end, figures in $(OUT)/"
	@echo "make test            whole regression (pytest -n $(JOBS))"
	@echo "make sim BLOCK=name  one block's cocotb testbench (tb/name)"
	@echo "make lint            Verilator --lint-only -Wall on every RTL module"
	@echo "make gen             regenerate generated RTL (rtl/fft/fft_rom_pkg.sv, fft_*_rom.sv,"
	@echo "                     rtl/buffers/packet_crc32.sv, the register map's files) and check it"
	@echo "make regs            regenerate from rtl/regs/radar_regs.rdl: register block, C header,"
	@echo "                     HTML map, Python map (docs/regs.md) and check them"
	@echo "make bench           model and host benchmarks (print tables)"
	@echo "make bench-rtl       FFT core, radar_pipeline and frame_store_axi benchmarks (Verilator)"
	@echo "make bench-openradar this chain vs OpenRadar 1.0.1 (own venv in $(OUT)/) on the real TI frame"
	@echo "make soak            SOAK_FRAMES=1000 paper-fpga frames, C++ harness, random stalls"
	@echo "make test-full       one full-size frame, FRAME_STORE=1 top + AXI4 memory, bit-exact"
	@echo "make test-full-detect  Table I full frame, OUTPUT_MODE=1 + FRAME_STORE=1, records bit-exact"
	@echo "make test-detect-long  detector blocks and the mode-1 top at every parameter set"
	@echo "make test-process-rtl  the OpenRadar capture, --backend rtl = model, every chain"
	@echo "make synth-estimate  Yosys resource estimate (paper-fpga blocks + top) -> $(OUT)/synth/"
	@echo "make synth-vivado    Vivado synthesis for the ZCU106 (needs vivado on PATH)"
	@echo "make timing          ECP5-85 place and route + xcup LUT depth per block -> $(OUT)/timing/"
	@echo "make gnn-dataset     synthetic labelled dataset (700/500/200 frames, ~25 min)"
	@echo "make gnn-train       train the GNN on it (~7 min on 2 cores)"
	@echo "make gnn-eval        GNN vs DBSCAN baseline on the 200 test frames -> out/gnn_eval.json"
	@echo "make view            live browser view of the Table I replay at http://127.0.0.1:8050/"
	@echo "make view-records    the same, as the on-chip detector's record stream (--detect fpga)"
	@echo "make bench-view      browser display updates/s and memory of radar view (table)"
	@echo "make formal          SymbiYosys proofs of formal/*.sby (k-induction, bmc, cover), table;"
	@echo "                     FORMAL_ARGS='cfar_2d -t bmc' runs a subset"
	@echo "make coverage        Verilator line/toggle coverage of the block testbenches, table"
	@echo "make mutate          mutation testing of rtl/ (MUTANTS=40 SEED=1), score per module"
	@echo "make curves          Pd vs SNR against theory, RMSE vs CRB on Ray (CURVES_ARGS=--quick),"
	@echo "                     $(OUT)/curves.json and docs/img/pd_*.png, crb_*.png (docs/curves.md)"
	@echo "make bench-ray       the Monte-Carlo layer: 1 vs 2 Ray workers in the same run"
	@echo "make clean           remove build products (keeps .venv)"

setup: $(STAMP)
	@tools/install-chromium.sh

$(STAMP): pyproject.toml
	test -x $(VENV)/bin/python || $(PYTHON) -m venv $(VENV)
	$(VENV)/bin/python -m pip install --quiet --upgrade pip
	$(VENV)/bin/python -m pip install --quiet -e '.[dev]'
	tools/install-chromium.sh
	touch $@

demo: $(STAMP)
	$(RUN) radar demo --out $(OUT)

test: $(STAMP)
	$(RUN) pytest -n $(JOBS)

test-python: $(STAMP)
	$(RUN) pytest -n $(JOBS) tests

sim: $(STAMP)
	@test -n "$(BLOCK)" || { echo "usage: make sim BLOCK=<name> (a folder of tb/)"; exit 2; }
	@test -d tb/$(BLOCK) || { echo "no testbench tb/$(BLOCK)"; exit 2; }
	$(RUN) pytest -n $(JOBS) tb/$(BLOCK)

lint: $(STAMP)
	$(RUN) tools/lint.sh
	$(RUN) ruff check model rtlsim host gnn radar tb tests tools synth benchmarks

# Generated RTL: rewritten only here (never by a test); the up-to-date test then checks it.
gen: $(STAMP) regs
	$(RUN) python -m model.fft_rom
	$(RUN) python -m model.packet_crc
	$(RUN) pytest -q -n 0 tb/fft_axis/test_fft_axis_model.py tests/test_packet_crc.py -k up_to_date

# Everything generated from the SystemRDL register map (tools/gen_regs.py, docs/regs.md)
regs: $(STAMP)
	$(RUN) python tools/gen_regs.py
	$(RUN) pytest -q -n 0 tests/test_regs.py -k up_to_date

bench: $(STAMP)
	$(RUN) python -m benchmarks.bench_simulate
	$(RUN) python -m benchmarks.bench_model
	$(RUN) python -m benchmarks.bench_host
	$(RUN) python -m benchmarks.bench_detect
	$(RUN) python -m benchmarks.bench_unfold
	$(RUN) python -m benchmarks.bench_mcap
	$(RUN) python -m benchmarks.bench_impairments

# OpenRadar (the peer library) in its own virtualenv: openradar 1.0.1 does not declare its
# dependencies (scikit-learn among them); benchmarks/bench_openradar.py runs it in a subprocess
OPENRADAR_VENV := $(OUT)/openradar-venv
$(OPENRADAR_VENV)/.installed:
	$(PYTHON) -m venv $(OPENRADAR_VENV)
	$(OPENRADAR_VENV)/bin/python -m pip install --quiet openradar==1.0.1 'numpy>=2' scipy scikit-learn
	touch $@

bench-openradar: $(STAMP) $(OPENRADAR_VENV)/.installed
	$(RUN) python -m benchmarks.bench_openradar --peer-python $(OPENRADAR_VENV)/bin/python

bench-rtl: $(STAMP)
	$(RUN) python tb/fft_axis/bench_fft_axis.py
	$(RUN) python tb/radar_pipeline/bench_radar_pipeline.py
	$(RUN) python tb/radar_pipeline/bench_harness.py
	$(RUN) python tb/frame_store_axi/bench_frame_store_axi.py

# not part of `make test`: SOAK_FRAMES paper-fpga frames through the C++ harness, chunks
# alternating FRAME_STORE = 0 / 1 (AXI4 memory stalls), payload and status vs the model
SOAK_FRAMES ?= 1000
soak: $(STAMP)
	$(RUN) python -m rtlsim.harness.soak --frames $(SOAK_FRAMES)

include synth/synth.mk

# Verification beyond simulation (README "Verification"): not part of `make test`, except
# the tool sanity checks in tests/test_verif_tools.py (the fixed mutant subset runs there only
# with MUTATE_CI=1: `make mutate-ci`).
MUTANTS ?= 40
SEED    ?= 1

formal: $(STAMP)
	$(RUN) python tools/formal.py $(FORMAL_ARGS)

coverage: $(STAMP)
	$(RUN) python tools/coverage.py

mutate: $(STAMP)
	$(RUN) python tools/mutate.py -n $(MUTANTS) --seed $(SEED)

mutate-ci: $(STAMP)
	MUTATE_CI=1 $(RUN) pytest -q -n 0 tests/test_verif_tools.py

# Detection and estimation curves against theory on a local Ray (RAY_ADDRESS: a cluster);
# rerunning resumes from $(OUT)/curves.campaign.jsonl. CURVES_ARGS= for the full grids.
CURVES_ARGS ?= --quick
curves: $(STAMP)
	$(RUN) radar curves $(CURVES_ARGS) --json $(OUT)/curves.json --plots docs/img

bench-ray: $(STAMP)
	$(RUN) python -m benchmarks.bench_ray

# Every (input gap, output backpressure) stall-regime pair of tb/stall_regimes.py (16 per
# parameter set) instead of the 4-pair CI subset that `make test` runs
STALL_TBS ?= tb/frame_align tb/corner_turn tb/axis_packetizer tb/chirp_pingpong
.PHONY: test-stall
test-stall: $(STAMP)
	STALL_CROSS=full $(RUN) pytest -n $(JOBS) $(STALL_TBS)

GNN_CACHE ?= $(HOME)/.cache/radar-gnn

gnn-dataset: $(STAMP)
	$(RUN) radar gnn dataset --train 700 --val 500 --test 200 --workers 2

gnn-train: $(STAMP)
	$(RUN) radar gnn train --epochs 50 --hidden 64 --layers 3 \
	  --data $(GNN_CACHE)/train.npz $(GNN_CACHE)/val.npz

gnn-eval: $(STAMP)
	mkdir -p $(OUT)
	$(RUN) radar gnn eval --json $(OUT)/gnn_eval.json
	$(RUN) python -m benchmarks.bench_infer

clean:
	rm -rf sim_build $(OUT) .pytest_cache .ruff_cache
	find . -name __pycache__ -not -path './$(VENV)/*' -prune -exec rm -rf {} +
	find . -name '*.result.xml' -not -path './$(VENV)/*' -delete

# ---- radar view (live browser view) --------------------------------------------------------
VIEW_CAPTURE ?= $(OUT)/table1_paper-fpga.dmacap

$(VIEW_CAPTURE): | $(STAMP)
	mkdir -p $(dir $@)
	$(RUN) radar capture --scene table1 --preset paper-fpga --frames 8 --out $@

view: $(STAMP) $(VIEW_CAPTURE)
	$(RUN) radar view --replay $(VIEW_CAPTURE) --gnn --ego-speed 27.78

# the same scene as the on-chip detector's record stream (OUTPUT_MODE = 1)
VIEW_RECORDS ?= $(OUT)/table1_paper-fpga_records2.dmacap

$(VIEW_RECORDS): | $(STAMP)
	mkdir -p $(dir $@)
	$(RUN) radar capture --scene table1 --preset paper-fpga --frames 8 --detect fpga --out $@

view-records: $(STAMP) $(VIEW_RECORDS)
	$(RUN) radar view --replay $(VIEW_RECORDS) --gnn --ego-speed 27.78

bench-view: $(STAMP)
	$(RUN) python -m benchmarks.bench_view

# On-chip detection blocks at every parameter set (make test runs a quick subset)
.PHONY: test-detect-long
test-detect-long: $(STAMP)
	DETECT_LONG=1 $(RUN) pytest -n $(JOBS) tb/nci tb/cfar_2d tb/detect_records tb/detect_chain \
	  tb/radar_pipeline/test_radar_pipeline_detect.py tests/test_detect_fpga.py

# The OpenRadar capture through `radar process --backend rtl` against --backend model with
# static-clutter removal and the on-chip detector too (a build each; make test runs the plain
# chain only)
.PHONY: test-process-rtl
test-process-rtl: $(STAMP)
	PROCESS_RTL=1 $(RUN) pytest -q -n 0 tests/test_process_rtl.py

# One full-size frame (4 TX x 16 RX, 256 x 256) through the FRAME_STORE = 1 top and the C++
# harness's AXI4 memory, every DMA byte against the model (not in `make test`: the 16-lane
# build takes about ten minutes)
.PHONY: test-full
test-full: $(STAMP)
	FULL_FRAME=1 $(RUN) pytest -q -n 0 -s tb/radar_pipeline/test_harness.py -k full_frame_store

.PHONY: test-full-detect
test-full-detect: $(STAMP)
	FULL_DETECT=1 $(RUN) pytest -q -n 0 -s tb/radar_pipeline/test_harness.py -k full_frame_store_detect
