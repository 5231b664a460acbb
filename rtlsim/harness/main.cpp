// SPDX-License-Identifier: Apache-2.0
// Verilator-native harness of radar_pipeline: C++ drives every clock, no Python per cycle.
//
// Built by rtlsim's harness module (verilator --cc --exe --build) together with a generated
// "harness_config.h" that includes the Verilated top, names it `Top`, and lists the status
// ports (HARNESS_STATUS(X)), and, for FRAME_STORE = 1 tops, defines HARNESS_FRAME_STORE so the
// AXI4 memory model (axi4_mem.h) answers the top's m_axi_mem_* master port.
//
// Input (--adc): little-endian uint32 records, one per ADC beat: flags (bit 0 TLAST, bit 1
// TUSER[0] = frame start), then NUM_RX words {Q, I}. The beats of --frames frames, in order.
// Output (--dma): per TLAST-closed DMA packet a uint32 word count, then its words x NUM_RX
// uint32 lanes. Output (--status): JSON with cycles, wall and CPU time (wall_s, cpu_s) and,
// per segment, the status ports read after the segment drained (FRAME_STORE = 1: also the
// memory model's beats written / read and protocol errors during the segment).
//
// Run: --segment-frames K streams K frames, waits for their --packets-per-frame packets
// each, reads the status, then pulses rst (8 cycles) before the next segment (0: one
// segment). Random ADC gaps (TVALID low with probability --adc-gap per cycle, plus
// --chirp-gap idle cycles after each chirp), DMA backpressure (TREADY low with probability
// --dma-stall) and memory stalls come from one seed (--seed): the same arguments give the
// same cycles. --cfar-scales HEX,HEX,... are written to the register table CFAR_SCALE over
// AXI4-Lite after every reset (OUTPUT_MODE = 1: the CFAR threshold scale of each range edge,
// model.radar_pipeline.PipelineParams.cfar_scales); the other registers keep their reset
// values. --quiet N: a segment also ends once its input is sent and no DMA word came
// for N cycles (for runs that lose frames on purpose; 0: every packet must arrive). Exit status: 0 ok, 2 bad arguments or files, 3 timeout (no DMA word for
// --timeout cycles while packets are missing).
#include <verilated.h>

#include <chrono>
#include <cinttypes>
#include <ctime>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "harness_config.h"
#include "harness_util.h"
#ifdef HARNESS_FRAME_STORE
#include "axi4_mem.h"
#endif

namespace {

struct Args {
  std::string adc, dma, status;
  int num_rx = 4;
  int frames = 0;
  int segment_frames = 0;
  int packets_per_frame = 1;
  uint64_t seed = 1;
  double adc_gap = 0.0;
  double dma_stall = 0.0;
  int chirp_gap = 0;
  uint64_t timeout = 1000000;
  uint64_t quiet = 0;
  int mem_latency = 20;
  double mem_stall = 0.0;
  std::vector<uint32_t> cfar_scales;  // CFAR_SCALE entries 0, 1, ...
};

// Comma-separated hex numbers (optional 0x), each below 2^32 -> their values; empty on error.
std::vector<uint32_t> parse_hex_list(const std::string& v) {
  std::vector<uint32_t> out;
  size_t at = 0;
  while (at <= v.size()) {
    size_t end = v.find(',', at);
    if (end == std::string::npos) end = v.size();
    std::string h = v.substr(at, end - at);
    if (h.rfind("0x", 0) == 0 || h.rfind("0X", 0) == 0) h = h.substr(2);
    if (h.empty() || h.size() > 8 ||
        h.find_first_not_of("0123456789abcdefABCDEF") != std::string::npos)
      return {};
    out.push_back(static_cast<uint32_t>(std::strtoul(h.c_str(), nullptr, 16)));
    at = end + 1;
  }
  return out;
}

constexpr uint32_t CFAR_SCALE_ADDR = 0x100;  // model.radar_regs_map: CFAR_SCALE, 4 bytes apart

[[noreturn]] void fail(int code, const std::string& msg) {
  std::fprintf(stderr, "radar_harness: %s\n", msg.c_str());
  std::exit(code);
}

Args parse(int argc, char** argv) {
  Args a;
  for (int i = 1; i < argc; ++i) {
    std::string k = argv[i];
    if (k.rfind("+", 0) == 0) continue;  // Verilator plusargs
    if (i + 1 >= argc) fail(2, "missing value after " + k);
    std::string v = argv[++i];
    if (k == "--adc") a.adc = v;
    else if (k == "--dma") a.dma = v;
    else if (k == "--status") a.status = v;
    else if (k == "--num-rx") a.num_rx = std::atoi(v.c_str());
    else if (k == "--frames") a.frames = std::atoi(v.c_str());
    else if (k == "--segment-frames") a.segment_frames = std::atoi(v.c_str());
    else if (k == "--packets-per-frame") a.packets_per_frame = std::atoi(v.c_str());
    else if (k == "--seed") a.seed = std::strtoull(v.c_str(), nullptr, 0);
    else if (k == "--adc-gap") a.adc_gap = std::atof(v.c_str());
    else if (k == "--dma-stall") a.dma_stall = std::atof(v.c_str());
    else if (k == "--chirp-gap") a.chirp_gap = std::atoi(v.c_str());
    else if (k == "--timeout") a.timeout = std::strtoull(v.c_str(), nullptr, 0);
    else if (k == "--quiet") a.quiet = std::strtoull(v.c_str(), nullptr, 0);
    else if (k == "--mem-latency") a.mem_latency = std::atoi(v.c_str());
    else if (k == "--mem-stall") a.mem_stall = std::atof(v.c_str());
    else if (k == "--cfar-scales") {
      a.cfar_scales = parse_hex_list(v);
      if (a.cfar_scales.empty()) fail(2, "--cfar-scales must be comma-separated hex numbers");
    }
    else fail(2, "unknown option " + k);
  }
  if (a.adc.empty() || a.dma.empty() || a.status.empty()) fail(2, "need --adc, --dma, --status");
  if (a.frames <= 0) fail(2, "--frames must be > 0");
  if (a.num_rx < 1 || a.num_rx > 16) fail(2, "--num-rx must be 1..16");
  if (a.segment_frames <= 0 || a.segment_frames > a.frames) a.segment_frames = a.frames;
  if (a.adc_gap < 0 || a.adc_gap >= 1 || a.dma_stall < 0 || a.dma_stall >= 1 ||
      a.mem_stall < 0 || a.mem_stall >= 1)
    fail(2, "--adc-gap, --dma-stall, --mem-stall must be in [0, 1)");
  return a;
}

class Harness {
 public:
  explicit Harness(const Args& a) : a_(a), ctx_(new VerilatedContext) {
    ctx_->randReset(2);
    ctx_->randSeed(static_cast<int>(a.seed & 0x7fffffff));
    top_.reset(new Top{ctx_.get()});
    rng_adc_.seed(harness::stream_seed(a.seed, 1));
    rng_dma_.seed(harness::stream_seed(a.seed, 2));
#ifdef HARNESS_FRAME_STORE
    mem_.reset(new harness::Axi4Mem(
        a.mem_latency, a.mem_stall, harness::stream_seed(a.seed, 3),
        static_cast<int>(sizeof(std::declval<Top>().m_axi_mem_wdata))));
#endif
    load_adc();
    // the register block: after each reset the scale table is written (reset()), the other
    // settings keep their reset values (static-clutter removal on when built in,
    // STATIC_REMOVAL = 1)
    top_->s_axil_awvalid = 0;
    top_->s_axil_wvalid = 0;
    top_->s_axil_arvalid = 0;
    top_->s_axil_bready = 1;
    top_->s_axil_rready = 1;
  }

  int run() {
    auto t0 = std::chrono::steady_clock::now();
    const std::clock_t cpu0 = std::clock();
    std::FILE* dma = std::fopen(a_.dma.c_str(), "wb");
    if (!dma) fail(2, "cannot write " + a_.dma);
    dma_ = dma;
    std::string segs;
    for (int f0 = 0; f0 < a_.frames; f0 += a_.segment_frames) {
      int nf = std::min(a_.segment_frames, a_.frames - f0);
      reset();
      run_segment(f0, nf);
      if (!segs.empty()) segs += ", ";
      segs += status_json(nf);
    }
    std::fclose(dma);
    top_->final();
    double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    double cpu = static_cast<double>(std::clock() - cpu0) / CLOCKS_PER_SEC;
    std::FILE* st = std::fopen(a_.status.c_str(), "w");
    if (!st) fail(2, "cannot write " + a_.status);
    std::fprintf(st, "{\"cycles\": %" PRIu64 ", \"wall_s\": %.6f, \"cpu_s\": %.6f, "
                 "\"packets\": %" PRIu64 ", \"segments\": [%s]}\n", cycles_, wall, cpu,
                 packets_, segs.c_str());
    std::fclose(st);
    return 0;
  }

 private:
  void load_adc() {
    std::FILE* f = std::fopen(a_.adc.c_str(), "rb");
    if (!f) fail(2, "cannot read " + a_.adc);
    std::fseek(f, 0, SEEK_END);
    long bytes = std::ftell(f);
    std::fseek(f, 0, SEEK_SET);
    rec_ = 1 + a_.num_rx;
    if (bytes <= 0 || bytes % (4L * rec_) != 0) fail(2, "ADC file size not a whole number of beats");
    adc_.resize(static_cast<size_t>(bytes) / 4);
    if (std::fread(adc_.data(), 4, adc_.size(), f) != adc_.size()) fail(2, "short read " + a_.adc);
    std::fclose(f);
    size_t beats = adc_.size() / rec_;
    if (beats % a_.frames != 0) fail(2, "ADC beats not divisible by --frames");
    beats_per_frame_ = beats / a_.frames;
  }

  // One clock: inputs are already driven; settle at clk low, sample the handshakes (the
  // values a flop sees at the rising edge), then the edge.
  void tick() {
    top_->clk = 0;
#ifdef HARNESS_FRAME_STORE
    mem_->drive(*top_);
#endif
    top_->eval();
    adc_fire_ = top_->s_axis_adc_tvalid && top_->s_axis_adc_tready;
    if (top_->m_axis_dma_tvalid && top_->m_axis_dma_tready) {
      size_t at = packet_.size();
      packet_.resize(at + a_.num_rx);
      harness::get_words(top_->m_axis_dma_tdata, &packet_[at], a_.num_rx);
      last_dma_cycle_ = cycles_;
      if (top_->m_axis_dma_tlast) flush_packet();
    }
#ifdef HARNESS_FRAME_STORE
    mem_->sample(*top_, cycles_);
#endif
    top_->clk = 1;
    top_->eval();
    ++cycles_;
  }

  // One AXI4-Lite write (whole word), the handshakes sampled as tick() samples the streams'.
  void axil_write(uint32_t addr, uint32_t data) {
    top_->s_axil_awaddr = addr;
    top_->s_axil_awprot = 0;
    top_->s_axil_wdata = data;
    top_->s_axil_wstrb = 0xF;
    top_->s_axil_awvalid = 1;
    top_->s_axil_wvalid = 1;
    for (int i = 0; i < 64; ++i) {
      top_->clk = 0;
      top_->eval();
      bool aw = top_->s_axil_awvalid && top_->s_axil_awready;
      bool w = top_->s_axil_wvalid && top_->s_axil_wready;
      bool b = top_->s_axil_bvalid && top_->s_axil_bready;
      tick();
      if (aw) top_->s_axil_awvalid = 0;
      if (w) top_->s_axil_wvalid = 0;
      if (b) return;
    }
    fail(3, "AXI4-Lite write not answered");
  }

  void flush_packet() {
    uint32_t words = static_cast<uint32_t>(packet_.size() / a_.num_rx);
    std::fwrite(&words, 4, 1, dma_);
    std::fwrite(packet_.data(), 4, packet_.size(), dma_);
    packet_.clear();
    ++packets_;
    ++seg_packets_;
  }

  void reset() {
    top_->rst = 1;
    top_->s_axis_adc_tvalid = 0;
    top_->m_axis_dma_tready = 0;
    for (int i = 0; i < 8; ++i) tick();
    top_->rst = 0;
    for (int i = 0; i < 2; ++i) tick();
    for (size_t e = 0; e < a_.cfar_scales.size(); ++e)
      axil_write(CFAR_SCALE_ADDR + 4 * static_cast<uint32_t>(e), a_.cfar_scales[e]);
    packet_.clear();  // a packet cut by the reset is not a packet
#ifdef HARNESS_FRAME_STORE
    mem_->reset_channels();
    mem_at_reset_[0] = mem_->beats_written();
    mem_at_reset_[1] = mem_->beats_read();
    mem_at_reset_[2] = mem_->protocol_errors();
#endif
  }

  void run_segment(int f0, int nf) {
    size_t idx = static_cast<size_t>(f0) * beats_per_frame_;
    const size_t end = idx + static_cast<size_t>(nf) * beats_per_frame_;
    const uint64_t want = static_cast<uint64_t>(nf) * a_.packets_per_frame;
    seg_packets_ = 0;
    last_dma_cycle_ = cycles_;
    int gap_left = 0;
    bool valid = false;
    adc_fire_ = false;
    while (seg_packets_ < want) {
      // ADC source: once TVALID is up it stays up until the beat is taken (AXI4-Stream)
      if (!valid) {
        if (gap_left > 0) {
          --gap_left;
        } else if (idx < end && !harness::chance(rng_adc_, a_.adc_gap)) {
          const uint32_t* r = &adc_[idx * rec_];
          harness::put_words(top_->s_axis_adc_tdata, r + 1, a_.num_rx);
          top_->s_axis_adc_tlast = r[0] & 1u;
          top_->s_axis_adc_tuser = (r[0] >> 1) & 1u;
          valid = true;
        }
      }
      top_->s_axis_adc_tvalid = valid;
      top_->m_axis_dma_tready = !harness::chance(rng_dma_, a_.dma_stall);
      tick();
      if (valid && adc_fire_) {
        if ((adc_[idx * rec_] & 1u) && a_.chirp_gap > 0) gap_left = a_.chirp_gap;
        ++idx;
        valid = false;
      }
      if (a_.quiet && idx == end && cycles_ - last_dma_cycle_ > a_.quiet) break;
      if (cycles_ - last_dma_cycle_ > a_.timeout)
        fail(3, "timeout: no DMA word for " + std::to_string(a_.timeout) + " cycles, " +
                    std::to_string(seg_packets_) + " of " + std::to_string(want) +
                    " packets of frames " + std::to_string(f0) + ".." +
                    std::to_string(f0 + nf - 1) + " received, cycle " +
                    std::to_string(cycles_));
    }
    top_->s_axis_adc_tvalid = 0;
  }

  std::string status_json(int nf) const {
    std::string s = "{\"frames\": " + std::to_string(nf);
#define HARNESS_STATUS_FIELD(name) \
  s += ", \"" #name "\": " + std::to_string(static_cast<unsigned long long>(top_->name));
    HARNESS_STATUS(HARNESS_STATUS_FIELD)
#undef HARNESS_STATUS_FIELD
#ifdef HARNESS_FRAME_STORE
    // the memory model's counters since the segment's reset, like the top's counters
    s += ", \"mem_writes\": " + std::to_string(mem_->beats_written() - mem_at_reset_[0]) +
         ", \"mem_reads\": " + std::to_string(mem_->beats_read() - mem_at_reset_[1]) +
         ", \"mem_protocol_errors\": " +
         std::to_string(mem_->protocol_errors() - mem_at_reset_[2]);
#endif
    return s + "}";
  }

  Args a_;
  std::unique_ptr<VerilatedContext> ctx_;
  std::unique_ptr<Top> top_;
#ifdef HARNESS_FRAME_STORE
  std::unique_ptr<harness::Axi4Mem> mem_;
  uint64_t mem_at_reset_[3] = {0, 0, 0};  // beats written, read, protocol errors
#endif
  std::mt19937_64 rng_adc_, rng_dma_;
  std::vector<uint32_t> adc_;
  size_t rec_ = 5, beats_per_frame_ = 0;
  std::vector<uint32_t> packet_;
  std::FILE* dma_ = nullptr;
  uint64_t cycles_ = 0, packets_ = 0, seg_packets_ = 0, last_dma_cycle_ = 0;
  bool adc_fire_ = false;
};

}  // namespace

int main(int argc, char** argv) {
  Args a = parse(argc, argv);
  Harness h(a);
  return h.run();
}
