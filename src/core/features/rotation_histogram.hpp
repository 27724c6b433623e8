#pragma once
// Rotation consistency: between two views every true match turns by about the same angle, so
// matches are binned by the difference of their keypoint angles and only the three most
// populated bins are kept (the ORB-SLAM check), ruling out most wrong matches.
#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

namespace hiveslam::features {

class RotationHistogram {
 public:
  static constexpr int kBins = 30;
  void add(float angle1_deg, float angle2_deg, int match) {
    float d = angle1_deg - angle2_deg;
    if (d < 0) d += 360.0f;
    int bin = static_cast<int>(std::lround(d * kBins / 360.0f));
    if (bin == kBins) bin = 0;
    bins_[static_cast<size_t>(bin)].push_back(match);
  }
  // Matches outside the three largest bins (a bin under a tenth of the largest is not kept).
  std::vector<int> rejected() const {
    std::array<int, kBins> order{};
    for (int i = 0; i < kBins; ++i) order[static_cast<size_t>(i)] = i;
    std::sort(order.begin(), order.end(), [&](int a, int b) { return size(a) > size(b); });
    const size_t top = size(order[0]);
    std::vector<int> out;
    for (int r = 0; r < kBins; ++r) {
      const int b = order[static_cast<size_t>(r)];
      const bool keep = r < 3 && size(b) * 10 >= top;
      if (!keep) out.insert(out.end(), bins_[static_cast<size_t>(b)].begin(), bins_[static_cast<size_t>(b)].end());
    }
    return out;
  }
  // The entries of `matches` that pass, for matches added with their position there as id.
  template <class T>
  std::vector<T> kept(const std::vector<T>& matches) const {
    std::vector<bool> drop(matches.size(), false);
    for (int k : rejected()) drop[static_cast<size_t>(k)] = true;
    std::vector<T> out;
    for (size_t k = 0; k < matches.size(); ++k)
      if (!drop[k]) out.push_back(matches[k]);
    return out;
  }

 private:
  size_t size(int bin) const { return bins_[static_cast<size_t>(bin)].size(); }
  std::array<std::vector<int>, kBins> bins_;
};

}  // namespace hiveslam::features
