#include "core/matching/initial_matcher.hpp"

#include <limits>

#include "core/features/hamming.hpp"
#include "core/features/rotation_histogram.hpp"

namespace hiveslam::core {

std::vector<int> matchForInitialization(const Frame& f1, const Frame& f2, const InitialMatchOptions& o,
                                        const std::vector<Eigen::Vector2d>* around) {
  std::vector<int> match12(f1.size(), -1);
  std::vector<int> match21(f2.size(), -1);
  std::vector<int> dist21(f2.size(), std::numeric_limits<int>::max());
  for (size_t i = 0; i < f1.size(); ++i) {
    const auto& kp = f1.keypoints[i];
    const auto& p = around ? (*around)[i] : f1.points[i];
    features::NearestTwo near;
    f2.forEachInRadius(p.x(), p.y(), o.radius, [&](int j) {
      if (f2.keypoints[static_cast<size_t>(j)].octave != kp.octave) return;
      const int d = features::hamming(f1.descriptors.ptr<uchar>(static_cast<int>(i)), f2.descriptors.ptr<uchar>(j));
      if (d > dist21[static_cast<size_t>(j)]) return;  // f2's keypoint already has a closer match
      near.offer(d, j);
    });
    if (!near.accepted(o.max_distance, o.ratio)) continue;
    const int best = near.best;
    const size_t j = static_cast<size_t>(near.index);
    if (match21[j] >= 0) match12[static_cast<size_t>(match21[j])] = -1;  // displaced
    match12[i] = near.index;
    match21[j] = static_cast<int>(i);
    dist21[j] = best;
  }
  if (o.check_rotation) {
    features::RotationHistogram hist;
    for (size_t i = 0; i < f1.size(); ++i)
      if (match12[i] >= 0) hist.add(f1.keypoints[i].angle, f2.keypoints[static_cast<size_t>(match12[i])].angle, static_cast<int>(i));
    for (int i : hist.rejected()) match12[static_cast<size_t>(i)] = -1;
  }
  return match12;
}

}  // namespace hiveslam::core
