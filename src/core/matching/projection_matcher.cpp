#include "core/matching/projection_matcher.hpp"

#include <limits>

#include "core/features/hamming.hpp"
#include "core/features/rotation_histogram.hpp"

namespace hiveslam::core {

int bestNear(const Frame& frame, const Eigen::Vector2d& uv, double radius, int min_level, int max_level,
             const unsigned char* descriptor, int max_distance, int* distance) {
  int best = std::numeric_limits<int>::max(), best_i = -1;
  frame.forEachInRadius(uv.x(), uv.y(), radius, [&](int i) {
    const int level = frame.keypoints[static_cast<size_t>(i)].octave;
    if (level < min_level || level > max_level) return;
    const int d = features::hamming(descriptor, frame.descriptors.ptr<uchar>(i));
    if (d < best) {
      best = d;
      best_i = i;
    }
  });
  if (best > max_distance) return -1;
  if (distance) *distance = best;
  return best_i;
}

int matchFromLastFrame(const Frame& current, const Eigen::Isometry3d& T_cw, PointSlots& current_points,
                       const Frame& last, const PointSlots& last_points, const std::vector<bool>& last_outliers,
                       double radius, const std::vector<double>& scales, bool check_rotation) {
  features::RotationHistogram hist;
  std::vector<int> matched;
  for (size_t j = 0; j < last_points.size(); ++j) {
    const auto& p = last_points[j];
    if (!p || p->bad || (j < last_outliers.size() && last_outliers[j])) continue;
    const Eigen::Vector3d pc = T_cw * p->position;
    if (pc.z() <= 0) continue;
    const Eigen::Vector2d uv = current.K.project(pc);
    const int level = last.keypoints[j].octave;
    const int i = bestNear(current, uv, radius * scales[static_cast<size_t>(level)], level - 1, level + 1,
                           p->descriptor.ptr<uchar>(), kMatchHigh);
    if (i < 0 || current_points[static_cast<size_t>(i)]) continue;
    current_points[static_cast<size_t>(i)] = p;
    matched.push_back(i);
    hist.add(last.keypoints[j].angle, current.keypoints[static_cast<size_t>(i)].angle, i);
  }
  int n = static_cast<int>(matched.size());
  if (check_rotation)
    for (int i : hist.rejected()) {
      current_points[static_cast<size_t>(i)].reset();
      --n;
    }
  return n;
}

int matchLocalMap(const Frame& frame, const Eigen::Isometry3d& T_cw, PointSlots& points,
                  const std::vector<std::shared_ptr<MapPoint>>& candidates, double radius_factor,
                  const std::vector<double>& scales) {
  const Eigen::Isometry3d T_wc = T_cw.inverse();
  int n = 0;
  for (const auto& p : candidates) {
    if (!p || p->bad) continue;
    const Eigen::Vector3d pc = T_cw * p->position;
    if (pc.z() <= 0) continue;
    const Eigen::Vector2d uv = frame.K.project(pc);
    if (!frame.inImage(uv)) continue;
    const Eigen::Vector3d ray = p->position - T_wc.translation();
    const double dist = ray.norm();
    if (dist < 0.8 * p->min_distance || dist > 1.2 * p->max_distance) continue;
    const double view_cos = ray.dot(p->normal) / dist;
    if (view_cos < 0.5) continue;
    ++p->visible;
    const int level = p->predictLevel(dist, scales);
    const double r = (view_cos > 0.998 ? 2.5 : 4.0) * radius_factor * scales[static_cast<size_t>(level)];
    const int i = bestNear(frame, uv, r, level - 1, level, p->descriptor.ptr<uchar>(), kMatchHigh);
    if (i < 0 || points[static_cast<size_t>(i)]) continue;
    points[static_cast<size_t>(i)] = p;
    ++n;
  }
  return n;
}

}  // namespace hiveslam::core
