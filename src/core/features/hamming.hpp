#pragma once
// Hamming distance of two 256-bit descriptors (32-byte rows), by popcount on 64-bit words.
#include <cstdint>
#include <cstring>

namespace hiveslam::features {

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

// The nearest and second-nearest descriptor distances offered so far, for the ratio test that
// every matcher applies: a match counts only when it is clearly better than the runner-up.
struct NearestTwo {
  int best = 257, second = 257, index = -1;
  void offer(int distance, int i) {
    if (distance < best) {
      second = best;
      best = distance;
      index = i;
    } else if (distance < second) {
      second = distance;
    }
  }
  bool accepted(int max_distance, double ratio) const {
    return index >= 0 && best <= max_distance && best < ratio * second;
  }
};

}  // namespace hiveslam::features
