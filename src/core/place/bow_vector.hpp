#pragma once
// The bag-of-words image descriptions produced by a Vocabulary.
//   BowVector: word -> TF-IDF weight, L1-normalized (what place recognition scores).
//   FeatureVector: vocabulary node a few levels above the words -> the features under it, so
//   two images are matched feature by feature only within the same node (BoW matching).
#include <cmath>
#include <cstdint>
#include <map>
#include <vector>

namespace hiveslam::place {

using WordId = uint32_t;
using NodeId = uint32_t;
using BowVector = std::map<WordId, double>;
using FeatureVector = std::map<NodeId, std::vector<int>>;

// L1 score in [0, 1]: 1 - |a - b|_1 / 2 for L1-normalized vectors (only shared words count).
inline double scoreL1(const BowVector& a, const BowVector& b) {
  double s = 0;
  auto i = a.begin();
  auto j = b.begin();
  while (i != a.end() && j != b.end()) {
    if (i->first < j->first) {
      i = a.lower_bound(j->first);
    } else if (j->first < i->first) {
      j = b.lower_bound(i->first);
    } else {
      const double x = i->second, y = j->second;
      s += std::abs(x) + std::abs(y) - std::abs(x - y);
      ++i;
      ++j;
    }
  }
  return 0.5 * s;
}

}  // namespace hiveslam::place
