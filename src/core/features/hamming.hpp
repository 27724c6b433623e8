#pragma once
// Descriptor distances for the matchers: the Hamming distance (common/hamming.hpp) and the ratio test.
#include "common/hamming.hpp"

namespace hiveslam::features {

using hiveslam::hamming;
using hiveslam::popcount64;

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
