#pragma once
// Hamming distance of two 256-bit descriptors (32-byte rows), by popcount on 64-bit words.
// Header-only in common: the core's matchers and the renderer's image statistics share it.
#include <cstdint>
#include <cstring>

namespace hiveslam {

// Bit count of a 64-bit word by the parallel (SWAR) method, inline: baseline x86-64 has no
// popcount instruction, and std::popcount there is a library call per word.
inline int popcount64(uint64_t v) {
  v = v - ((v >> 1) & 0x5555555555555555ULL);
  v = (v & 0x3333333333333333ULL) + ((v >> 2) & 0x3333333333333333ULL);
  v = (v + (v >> 4)) & 0x0f0f0f0f0f0f0f0fULL;
  return static_cast<int>((v * 0x0101010101010101ULL) >> 56);
}

inline int hamming(const unsigned char* a, const unsigned char* b) {
  int d = 0;
  for (int i = 0; i < 4; ++i) {
    uint64_t x, y;
    std::memcpy(&x, a + 8 * i, 8);
    std::memcpy(&y, b + 8 * i, 8);
    d += popcount64(x ^ y);
  }
  return d;
}

}  // namespace hiveslam
