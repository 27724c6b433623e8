#include "core/matching/fusion.hpp"

#include "core/matching/projection_matcher.hpp"

namespace hiveslam::core {

int fusePoints(Map& map, KeyFrame& kf, std::vector<std::shared_ptr<MapPoint>> points,
              const std::vector<double>& scales) {
  int fused = 0;
  const Eigen::Vector3d C = kf.center();
  for (const auto& p : points) {
    if (!p || p->bad || p->observations.count(&kf)) continue;
    const Eigen::Vector3d pc = kf.T_cw * p->position;
    if (pc.z() <= 0) continue;
    const Eigen::Vector2d uv = kf.frame.K.project(pc);
    if (!kf.frame.inImage(uv)) continue;
    const Eigen::Vector3d ray = p->position - C;
    const double dist = ray.norm();
    if (dist < 0.8 * p->min_distance || dist > 1.2 * p->max_distance || ray.dot(p->normal) < 0.5 * dist) continue;
    const int level = p->predictLevel(dist, scales);
    const double s = scales[static_cast<size_t>(level)];
    const int j = bestNear(kf.frame, uv, 3.0 * s, level - 1, level + 1, p->descriptor.ptr<uchar>(), kMatchLow);
    if (j < 0) continue;
    const double s_kp = scales[static_cast<size_t>(kf.frame.keypoints[static_cast<size_t>(j)].octave)];
    if ((kf.frame.points[static_cast<size_t>(j)] - uv).squaredNorm() > 5.991 * s_kp * s_kp) continue;
    auto existing = kf.points[static_cast<size_t>(j)];
    if (existing && !existing->bad) {
      if (existing == p) continue;
      if (existing->observations.size() > p->observations.size()) map.replace(*p, existing);
      else map.replace(*existing, p);
    } else {
      Map::observe(kf, j, p);
    }
    ++fused;
  }
  return fused;
}


}  // namespace hiveslam::core
