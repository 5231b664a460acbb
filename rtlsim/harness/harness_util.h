// SPDX-License-Identifier: Apache-2.0
// Helpers of the Verilator-native harness: move uint32 lanes in and out of Verilated ports of
// any width, and a seeded, platform-independent coin flip.
#pragma once

#include <cstddef>
#include <cstdint>
#include <random>

#ifdef VERILATOR_VERILATED_H_
#define HARNESS_HAVE_VERILATED 1
#endif

namespace harness {

// Ports up to 32 bits (IData, CData, SData).
template <typename T>
inline void put_words(T& port, const uint32_t* v, int n) {
  (void)n;
  port = static_cast<T>(v[0]);
}
inline void put_words(uint64_t& port, const uint32_t* v, int n) {
  port = v[0] | (n > 1 ? static_cast<uint64_t>(v[1]) << 32 : 0);
}
template <typename T>
inline void get_words(const T& port, uint32_t* v, int n) {
  (void)n;
  v[0] = static_cast<uint32_t>(port);
}
inline void get_words(const uint64_t& port, uint32_t* v, int n) {
  v[0] = static_cast<uint32_t>(port);
  if (n > 1) v[1] = static_cast<uint32_t>(port >> 32);
}
#ifdef HARNESS_HAVE_VERILATED
// Wide ports (> 64 bits): VlWide<N> of 32-bit words, word 0 = bits 31:0.
template <std::size_t N>
inline void put_words(VlWide<N>& port, const uint32_t* v, int n) {
  for (std::size_t i = 0; i < N; ++i) port[i] = i < static_cast<std::size_t>(n) ? v[i] : 0;
}
template <std::size_t N>
inline void get_words(const VlWide<N>& port, uint32_t* v, int n) {
  for (int i = 0; i < n && static_cast<std::size_t>(i) < N; ++i) v[i] = port[i];
}
#endif

// Seed of random stream `k` (ADC gaps, DMA stalls, memory stalls) of run seed `seed`.
inline uint64_t stream_seed(uint64_t seed, uint64_t k) {
  std::seed_seq seq{static_cast<uint32_t>(seed), static_cast<uint32_t>(seed >> 32),
                    static_cast<uint32_t>(k)};
  uint64_t out[1];
  uint32_t w[2];
  seq.generate(w, w + 2);
  out[0] = (static_cast<uint64_t>(w[1]) << 32) | w[0];
  return out[0];
}

// True with probability p (53-bit uniform from mt19937_64: same sequence on every platform).
inline bool chance(std::mt19937_64& rng, double p) {
  if (p <= 0.0) return false;
  return static_cast<double>(rng() >> 11) * 0x1.0p-53 < p;
}

}  // namespace harness
