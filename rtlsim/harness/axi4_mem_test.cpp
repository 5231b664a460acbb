// SPDX-License-Identifier: Apache-2.0
// Unit check of axi4_mem.h without any RTL: a random AXI4 master (writes with random
// strobes, reads back) against a reference byte array, with the memory's latency and random
// stalls. Checks data, the latency bound, VALID/data stability while stalled, protocol-error
// detection and determinism by seed. Built and run by tests/test_axi4_mem.py:
//   c++ -std=c++17 -I rtlsim/harness rtlsim/harness/axi4_mem_test.cpp && ./a.out
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <deque>
#include <random>
#include <string>
#include <vector>

#include "axi4_mem.h"

namespace {

int failures = 0;
void check(bool ok, const std::string& what) {
  if (!ok && failures++ < 10) std::fprintf(stderr, "FAIL: %s\n", what.c_str());
}

struct Op {
  bool write;
  uint64_t addr;
  uint32_t len;                  // beats - 1
  std::vector<uint8_t> data;     // (len+1) * bytes
  std::vector<uint64_t> strb;    // per beat
};

// Runs `n_ops` random bursts; returns the cycles taken.
uint64_t run(int latency, double stall, uint64_t seed, int bytes, int n_ops) {
  harness::Axi4Mem mem(latency, stall, seed, bytes);
  std::mt19937_64 rng(seed * 7 + 1);
  const uint64_t space = 1 << 16;
  std::vector<uint8_t> ref(space, 0);
  std::deque<Op> ops;
  for (int k = 0; k < n_ops; ++k) {
    Op op;
    op.write = k < 4 || rng() % 2;
    op.len = static_cast<uint32_t>(rng() % 16);
    uint64_t beats_in_page = 4096 / bytes;
    uint64_t first = rng() % (beats_in_page - op.len);  // INCR stays inside a 4 KiB page
    op.addr = (rng() % (space / 4096)) * 4096 + first * bytes;
    if (op.write) {
      for (uint32_t b = 0; b <= op.len; ++b) {
        op.strb.push_back(rng() & ((bytes == 64) ? ~0ull : ((1ull << bytes) - 1)));
        for (int i = 0; i < bytes; ++i) op.data.push_back(static_cast<uint8_t>(rng()));
      }
    }
    ops.push_back(op);
  }
  // one burst at a time, each fully completed (B or last R) before the next: the reference
  // is then exact without modelling write/read ordering
  uint64_t cycle = 0;
  uint32_t sz = 0;  // AxSIZE: full-width beats
  while ((1 << sz) < bytes) ++sz;
  for (const Op& op : ops) {
    harness::Axi4Mem::In in;
    bool addr_done = false, done = false;
    uint32_t beat = 0;
    uint64_t addr_cycle = 0, first_data_cycle = 0;
    bool have_first = false, prev_rvalid_stalled = false;
    uint32_t prev_rdata[harness::Axi4Mem::kMaxWords] = {};
    bool wlast_sent = false;
    uint64_t wlast_cycle = 0;
    while (!done) {
      const harness::Axi4Mem::Out& out = mem.out();
      in = harness::Axi4Mem::In{};
      in.awburst = in.arburst = 1;
      in.awsize = in.arsize = sz;
      if (op.write) {
        in.awvalid = !addr_done;
        in.awaddr = op.addr;
        in.awid = static_cast<uint32_t>(op.addr >> 12) & 7u;
        in.awlen = op.len;
        in.wvalid = addr_done && beat <= op.len && (rng() % 4 != 0);
        if (in.wvalid) {
          std::memcpy(in.wdata, &op.data[beat * bytes], bytes);
          in.wstrb = op.strb[beat];
          in.wlast = beat == op.len;
        }
        in.bready = rng() % 3 != 0;
        if (out.bvalid) {
          check(wlast_sent && cycle >= wlast_cycle + latency,
                "B before latency: cycle " + std::to_string(cycle));
          check(out.bid == (static_cast<uint32_t>(op.addr >> 12) & 7u), "BID not AWID");
          if (in.bready) done = true;
        }
        if (in.awvalid && out.awready) addr_done = true;
        if (in.wvalid && out.wready) {
          if (in.wlast) {
            wlast_sent = true;
            wlast_cycle = cycle;
          }
          ++beat;
        }
      } else {
        in.arvalid = !addr_done;
        in.araddr = op.addr;
        in.arid = static_cast<uint32_t>(op.addr >> 12) & 7u;
        in.arlen = op.len;
        in.rready = rng() % 3 != 0;
        if (prev_rvalid_stalled) {
          check(out.rvalid, "RVALID dropped before its handshake");
          check(std::memcmp(prev_rdata, out.rdata, bytes) == 0, "RDATA changed while stalled");
        }
        if (out.rvalid) {
          if (!have_first) {
            have_first = true;
            first_data_cycle = cycle;
            check(first_data_cycle >= addr_cycle + latency,
                  "first R beat " + std::to_string(first_data_cycle - addr_cycle) +
                      " cycles after AR, latency " + std::to_string(latency));
          }
          check(out.rlast == (beat == op.len), "RLAST on beat " + std::to_string(beat));
          check(out.rid == (static_cast<uint32_t>(op.addr >> 12) & 7u), "RID not ARID");
          if (in.rready) {
            const uint8_t* got = reinterpret_cast<const uint8_t*>(out.rdata);
            const uint64_t base = op.addr + uint64_t{beat} * bytes;
            for (int i = 0; i < bytes; ++i)
              check(got[i] == ref[base + i], "read data at 0x" + std::to_string(base + i));
            ++beat;
            if (beat > op.len) done = true;
          }
          std::memcpy(prev_rdata, out.rdata, sizeof prev_rdata);
        }
        prev_rvalid_stalled = out.rvalid && !in.rready;
        if (in.arvalid && out.arready) {
          addr_done = true;
          addr_cycle = cycle;
        }
      }
      mem.clock(in, cycle);
      ++cycle;
      if (cycle > 10'000'000) {
        check(false, "hang");
        return cycle;
      }
    }
    if (op.write) {
      for (uint32_t b = 0; b <= op.len; ++b)
        for (int i = 0; i < bytes; ++i)
          if ((op.strb[b] >> i) & 1u) ref[op.addr + uint64_t{b} * bytes + i] = op.data[b * bytes + i];
    }
  }
  check(mem.protocol_errors() == 0, "protocol error on a legal stream: " + mem.first_error());
  // memory content equals the reference everywhere
  for (uint64_t a = 0; a < space; ++a)
    if (mem.peek(a) != ref[a]) {
      check(false, "memory differs at 0x" + std::to_string(a));
      break;
    }
  return cycle;
}

void protocol_checks() {
  harness::Axi4Mem mem(2, 0.0, 1, 16);
  harness::Axi4Mem::In in;
  in.awvalid = true;
  in.awaddr = 4096 - 32;
  in.awlen = 3;  // 4 x 16 bytes from 4064: crosses 4 KiB
  in.awsize = 4;
  in.awburst = 1;
  mem.clock(in, 0);  // awready is high at cycle 0 without stalls
  check(mem.protocol_errors() == 1, "4 KiB crossing not flagged");
  in = harness::Axi4Mem::In{};
  in.wvalid = true;
  in.wstrb = 0xffff;
  in.wlast = true;  // early: beat 0 of 4
  mem.clock(in, 1);
  check(mem.protocol_errors() == 2, "early WLAST not flagged");
}

}  // namespace

int main() {
  uint64_t total = 0;
  for (int bytes : {4, 16, 64}) {
    for (int latency : {0, 1, 20}) {
      for (double stall : {0.0, 0.3, 0.7}) {
        uint64_t c1 = run(latency, stall, 11, bytes, 60);
        uint64_t c2 = run(latency, stall, 11, bytes, 60);
        check(c1 == c2, "not deterministic by seed");
        total += c1;
      }
    }
  }
  check(run(20, 0.5, 11, 64, 60) != run(20, 0.5, 12, 64, 60), "seed has no effect");
  protocol_checks();
  if (failures) {
    std::fprintf(stderr, "axi4_mem_test: %d failure(s)\n", failures);
    return 1;
  }
  std::printf("axi4_mem_test: ok, %llu cycles\n", static_cast<unsigned long long>(total));
  return 0;
}
