// SPDX-License-Identifier: Apache-2.0
// AXI4 memory (slave) model of the Verilator-native harness: the external frame store
// (DDR4 on the ZCU106) behind a FRAME_STORE = 1 radar_pipeline's m_axi_mem_* master port.
//
// - INCR, FIXED and WRAP bursts of up to 256 beats, any data width up to 512 bits, WSTRB
//   byte enables; sparse byte memory (4 KiB pages allocated on first touch, reads of
//   never-written bytes return 0).
// - Configurable latency: a read burst's first beat and a write response come no earlier
//   than `latency` clocks after the address (resp. last data) handshake; reads and writes
//   each complete in order (one ID), up to 8 outstanding addresses per direction.
// - Random stalls: with probability `stall` per clock AWREADY, WREADY, ARREADY are low and a
//   new RVALID / BVALID is held back (a raised VALID stays up until its handshake).
// - Protocol checks, counted (protocol_errors()) and the first one kept (first_error()):
//   INCR burst crossing 4 KiB, WLAST on the wrong beat, unaligned WRAP or bad WRAP length,
//   burst type 3, size above the data width.
// - IDs: BID / RID echo AWID / ARID; responses stay in order (allowed for any IDs).
//
// Core API (no Verilator types; unit-checked by axi4_mem_test.cpp): set In, read Out,
// call clock(). Out is what the slave drives during the current cycle; clock(in, cycle)
// takes the master's signals sampled just before the rising edge, performs the handshakes
// and computes the next Out. drive()/sample() bind it to a Verilated top's m_axi_mem_* ports.
#pragma once

#include <array>
#include <cstdio>
#include <cstdint>
#include <cstring>
#include <deque>
#include <memory>
#include <random>
#include <string>
#include <unordered_map>

#include "harness_util.h"

namespace harness {

class Axi4Mem {
 public:
  static constexpr int kMaxWords = 16;  // 512-bit data
  static constexpr size_t kMaxOutstanding = 8;

  struct In {
    bool awvalid = false;
    uint32_t awid = 0, arid = 0;
    uint64_t awaddr = 0;
    uint32_t awlen = 0, awsize = 0, awburst = 1;
    bool wvalid = false;
    uint32_t wdata[kMaxWords] = {};
    uint64_t wstrb = 0;
    bool wlast = false;
    bool bready = false;
    bool arvalid = false;
    uint64_t araddr = 0;
    uint32_t arlen = 0, arsize = 0, arburst = 1;
    bool rready = false;
  };
  struct Out {
    bool awready = false, wready = false, bvalid = false, arready = false, rvalid = false;
    bool rlast = false;
    uint32_t bresp = 0, rresp = 0, bid = 0, rid = 0;
    uint32_t rdata[kMaxWords] = {};
  };

  Axi4Mem(int latency, double stall, uint64_t seed, int data_bytes = 64)
      : latency_(latency < 0 ? 0 : latency), stall_(stall), bytes_(data_bytes) {
    rng_.seed(seed);
    next_out(0);
  }

  const Out& out() const { return out_; }

  // The handshakes of the cycle `cycle` (signals sampled before its rising edge).
  void clock(const In& in, uint64_t cycle) {
    // AW
    if (in.awvalid && out_.awready) {
      Burst b = make_burst(in.awaddr, in.awlen, in.awsize, in.awburst, cycle, in.awid);
      aw_.push_back(b);
    }
    // W: data of the oldest accepted write address
    if (in.wvalid && out_.wready) {
      Burst& b = aw_.front();
      uint64_t a = beat_addr(b);
      const int lo = static_cast<int>(a % bytes_) & ~((1 << b.size) - 1);
      const int hi = lo + (1 << b.size);
      const uint8_t* src = reinterpret_cast<const uint8_t*>(in.wdata);
      for (int i = 0; i < bytes_; ++i) {
        if (!((in.wstrb >> i) & 1u)) continue;
        if (i < lo || i >= hi) {
          error("WSTRB byte " + std::to_string(i) + " outside the transfer's byte lanes");
          continue;
        }
        byte(a - (a % bytes_) + i) = src[i];
      }
      bool last = b.beat == b.len;
      if (in.wlast != last) error("WLAST " + std::string(in.wlast ? "early" : "missing") +
                                  " on beat " + std::to_string(b.beat) + " of a " +
                                  std::to_string(b.len + 1) + "-beat write");
      ++written_;
      if (last) {
        b_.push_back({cycle + latency_, b.id});
        aw_.pop_front();
      } else {
        ++b.beat;
      }
    }
    // B
    if (out_.bvalid && in.bready) {
      b_.pop_front();
      bvalid_held_ = false;
    }
    // AR
    if (in.arvalid && out_.arready) ar_.push_back(make_burst(in.araddr, in.arlen, in.arsize,
                                                            in.arburst, cycle + latency_,
                                                            in.arid));
    // R
    if (out_.rvalid && in.rready) {
      Burst& b = ar_.front();
      ++read_;
      rvalid_held_ = false;
      if (b.beat == b.len) ar_.pop_front();
      else ++b.beat;
    }
    next_out(cycle + 1);
  }

  // Forget bursts in flight (the master was reset); memory contents stay.
  void reset_channels() {
    aw_.clear();
    ar_.clear();
    b_.clear();
    rvalid_held_ = bvalid_held_ = false;
    next_out(0);
  }

  uint64_t beats_written() const { return written_; }
  uint64_t beats_read() const { return read_; }
  uint64_t protocol_errors() const { return errors_; }
  const std::string& first_error() const { return first_error_; }

  // Direct access (test benches preload frames or check what was stored).
  uint8_t peek(uint64_t addr) { return byte(addr); }
  void poke(uint64_t addr, uint8_t v) { byte(addr) = v; }

#ifdef VERILATOR_VERILATED_H_
  // Bind to a Verilated top with AXI4 master ports m_axi_mem_* (no ID signals: one ID).
  template <class T>
  void drive(T& top) {
    top.m_axi_mem_awready = out_.awready;
    top.m_axi_mem_wready = out_.wready;
    top.m_axi_mem_bvalid = out_.bvalid;
    top.m_axi_mem_bresp = out_.bresp;
    top.m_axi_mem_bid = out_.bid;
    top.m_axi_mem_rid = out_.rid;
    top.m_axi_mem_arready = out_.arready;
    top.m_axi_mem_rvalid = out_.rvalid;
    top.m_axi_mem_rlast = out_.rlast;
    top.m_axi_mem_rresp = out_.rresp;
    put_words(top.m_axi_mem_rdata, out_.rdata, bytes_ / 4);
  }
  template <class T>
  void sample(T& top, uint64_t cycle) {
    In in;
    in.awvalid = top.m_axi_mem_awvalid;
    in.awid = top.m_axi_mem_awid;
    in.arid = top.m_axi_mem_arid;
    in.awaddr = top.m_axi_mem_awaddr;
    in.awlen = top.m_axi_mem_awlen;
    in.awsize = top.m_axi_mem_awsize;
    in.awburst = top.m_axi_mem_awburst;
    in.wvalid = top.m_axi_mem_wvalid;
    get_words(top.m_axi_mem_wdata, in.wdata, bytes_ / 4);
    in.wstrb = top.m_axi_mem_wstrb;
    in.wlast = top.m_axi_mem_wlast;
    in.bready = top.m_axi_mem_bready;
    in.arvalid = top.m_axi_mem_arvalid;
    in.araddr = top.m_axi_mem_araddr;
    in.arlen = top.m_axi_mem_arlen;
    in.arsize = top.m_axi_mem_arsize;
    in.arburst = top.m_axi_mem_arburst;
    in.rready = top.m_axi_mem_rready;
    clock(in, cycle);
  }
#endif

 private:
  struct Burst {
    uint64_t addr;
    uint32_t len, size, type, beat;
    uint64_t ready_at;
    uint32_t id;
  };
  struct Resp {
    uint64_t ready_at;
    uint32_t id;
  };

  Burst make_burst(uint64_t addr, uint32_t len, uint32_t size, uint32_t type, uint64_t at,
                   uint32_t id) {
    if (len > 255) error("burst length " + std::to_string(len + 1) + " > 256");
    if ((1 << size) > bytes_) error("AxSIZE " + std::to_string(size) + " above data width");
    if (type == 3) error("reserved burst type 3");
    if (type == 1) {
      uint64_t start = addr & ~((uint64_t{1} << size) - 1);
      uint64_t end = start + (uint64_t{len + 1} << size) - 1;
      if ((start >> 12) != (end >> 12)) error("INCR burst crosses a 4 KiB boundary at 0x" +
                                              hex(addr));
    }
    if (type == 2) {
      if (len != 1 && len != 3 && len != 7 && len != 15) error("WRAP length not 2/4/8/16");
      if (addr & ((uint64_t{1} << size) - 1)) error("unaligned WRAP burst");
    }
    return Burst{addr, len & 255u, size, type, 0, at, id};
  }

  uint64_t beat_addr(const Burst& b) const {
    const uint64_t n = uint64_t{1} << b.size;
    const uint64_t aligned = b.addr & ~(n - 1);
    if (b.type == 0) return b.addr;                                // FIXED
    if (b.type == 2) {                                            // WRAP
      const uint64_t span = n * (b.len + 1);
      const uint64_t base = b.addr & ~(span - 1);
      return base + ((b.addr - base + b.beat * n) % span);
    }
    return b.beat == 0 ? b.addr : aligned + b.beat * n;          // INCR
  }

  uint8_t& byte(uint64_t addr) {
    auto& page = pages_[addr >> 12];
    if (!page) page.reset(new std::array<uint8_t, 4096>{});
    return (*page)[addr & 4095];
  }

  void next_out(uint64_t cycle) {
    out_.awready = aw_.size() < kMaxOutstanding && !chance(rng_, stall_);
    out_.wready = !aw_.empty() && !chance(rng_, stall_);
    out_.arready = ar_.size() < kMaxOutstanding && !chance(rng_, stall_);
    if (!bvalid_held_) {
      bvalid_held_ = !b_.empty() && b_.front().ready_at <= cycle && !chance(rng_, stall_);
      if (bvalid_held_) out_.bid = b_.front().id;
    }
    out_.bvalid = bvalid_held_;
    out_.bresp = 0;
    if (!rvalid_held_) {
      rvalid_held_ = !ar_.empty() && ar_.front().ready_at <= cycle && !chance(rng_, stall_);
      if (rvalid_held_) {
        const Burst& b = ar_.front();
        uint64_t a = beat_addr(b);
        uint8_t* dst = reinterpret_cast<uint8_t*>(out_.rdata);
        std::memset(out_.rdata, 0, sizeof(out_.rdata));
        for (int i = 0; i < bytes_; ++i) dst[i] = byte(a - (a % bytes_) + i);
        out_.rlast = b.beat == b.len;
        out_.rid = b.id;
      }
    }
    out_.rvalid = rvalid_held_;
    out_.rresp = 0;
  }

  void error(const std::string& what) {
    if (errors_++ == 0) first_error_ = what;
  }

  static std::string hex(uint64_t v) {
    char buf[20];
    std::snprintf(buf, sizeof buf, "%llx", static_cast<unsigned long long>(v));
    return buf;
  }

  int latency_;
  double stall_;
  int bytes_;
  std::mt19937_64 rng_;
  Out out_;
  std::deque<Burst> aw_, ar_;
  std::deque<Resp> b_;
  bool rvalid_held_ = false, bvalid_held_ = false;
  uint64_t written_ = 0, read_ = 0, errors_ = 0;
  std::string first_error_;
  std::unordered_map<uint64_t, std::unique_ptr<std::array<uint8_t, 4096>>> pages_;
};

}  // namespace harness
