#pragma once
// Hamming distance of two 256-bit descriptors (32-byte rows), by popcount on 64-bit words.
#include <bit>
#include <cstdint>
#include <cstring>

namespace hiveslam::features {

inline int hamming(const unsigned char* a, const unsigned char* b) {
  int d = 0;
  for (int i = 0; i < 4; ++i) {
    uint64_t x, y;
    std::memcpy(&x, a + 8 * i, 8);
    std::memcpy(&y, b + 8 * i, 8);
    d += std::popcount(x ^ y);
  }
  return d;
}

}  // namespace hiveslam::features
