#include "core/matching/bow_matcher.hpp"

#include "core/features/hamming.hpp"
#include "core/features/rotation_histogram.hpp"
#include "core/map/map_point.hpp"
#include "core/matching/projection_matcher.hpp"

namespace hiveslam::core {

namespace {

// For every node shared by the two feature vectors, each usable feature of side A takes its
// nearest usable feature of side B among those `compatible` with it. Returns (a, b) pairs after
// the ratio and rotation tests.
template <typename UsableA, typename UsableB, typename Compatible>
std::vector<std::pair<int, int>> matchByNodes(const place::FeatureVector& fa, const cv::Mat& da,
                                              const std::vector<cv::KeyPoint>& ka, UsableA usable_a,
                                              const place::FeatureVector& fb, const cv::Mat& db,
                                              const std::vector<cv::KeyPoint>& kb, UsableB usable_b,
                                              Compatible compatible, double ratio) {
  std::vector<int> taken_b(static_cast<size_t>(db.rows), 0);
  std::vector<std::pair<int, int>> pairs;
  features::RotationHistogram hist;
  auto ia = fa.begin();
  auto ib = fb.begin();
  while (ia != fa.end() && ib != fb.end()) {
    if (ia->first < ib->first) {
      ia = fa.lower_bound(ib->first);
      continue;
    }
    if (ib->first < ia->first) {
      ib = fb.lower_bound(ia->first);
      continue;
    }
    for (int i : ia->second) {
      if (!usable_a(i)) continue;
      features::NearestTwo near;
      for (int j : ib->second)
        if (usable_b(j) && !taken_b[static_cast<size_t>(j)] && compatible(i, j)) near.offer(features::hamming(da.ptr<uchar>(i), db.ptr<uchar>(j)), j);
      if (!near.accepted(kMatchLow, ratio)) continue;
      const int best_j = near.index;
      taken_b[static_cast<size_t>(best_j)] = 1;
      hist.add(ka[static_cast<size_t>(i)].angle, kb[static_cast<size_t>(best_j)].angle, static_cast<int>(pairs.size()));
      pairs.emplace_back(i, best_j);
    }
    ++ia;
    ++ib;
  }
  return hist.kept(pairs);
}

auto hasPoint(const KeyFrame& kf) {
  return [&kf](int i) {
    const auto& p = kf.points[static_cast<size_t>(i)];
    return p && !p->bad;
  };
}

constexpr auto anyPair = [](int, int) { return true; };

}  // namespace

std::vector<std::pair<int, int>> matchKeyframesByBow(const KeyFrame& a, const KeyFrame& b, double ratio) {
  return matchByNodes(a.bow_features, a.frame.descriptors, a.frame.keypoints, hasPoint(a), b.bow_features,
                      b.frame.descriptors, b.frame.keypoints, hasPoint(b), anyPair, ratio);
}

std::vector<std::pair<int, int>> matchUnmappedByBow(const KeyFrame& a, const KeyFrame& b,
                                                    const std::function<bool(int, int)>& compatible, double ratio) {
  auto no_point = [](const KeyFrame& kf) {
    return [&kf](int i) { return !kf.points[static_cast<size_t>(i)]; };
  };
  return matchByNodes(a.bow_features, a.frame.descriptors, a.frame.keypoints, no_point(a), b.bow_features,
                      b.frame.descriptors, b.frame.keypoints, no_point(b), compatible, ratio);
}

std::vector<int> matchFrameByBow(const Frame& frame, const place::FeatureVector& frame_features, const KeyFrame& kf,
                                 double ratio) {
  std::vector<int> out(frame.size(), -1);
  const auto pairs = matchByNodes(
      frame_features, frame.descriptors, frame.keypoints, [](int) { return true; }, kf.bow_features,
      kf.frame.descriptors, kf.frame.keypoints, hasPoint(kf), anyPair, ratio);
  for (const auto& [i, j] : pairs) out[static_cast<size_t>(i)] = j;
  return out;
}

}  // namespace hiveslam::core
