#include "core/mapping/keyframe_gap.hpp"

#include <algorithm>
#include <cmath>

namespace hiveslam::core {

double viewAngleDegrees(const Eigen::Matrix3d& R_cw_a, const Eigen::Matrix3d& R_cw_b) {
  // The third row of R_cw is the camera's optical axis in the world frame.
  const double c = R_cw_a.row(2).dot(R_cw_b.row(2));
  return std::acos(std::clamp(c, -1.0, 1.0)) * 180.0 / M_PI;
}

bool cullingLeavesGap(const KeyFrame& k, double max_degrees) {
  if (max_degrees <= 0) return false;
  const double t = k.frame.timestamp;
  const KeyFrame *before = nullptr, *after = nullptr;
  for (const KeyFrame* o : k.bestCovisible(1000)) {
    if (o->bad) continue;
    const double s = o->frame.timestamp;
    if (s < t && (!before || s > before->frame.timestamp)) before = o;
    if (s > t && (!after || s < after->frame.timestamp)) after = o;
  }
  if (!before || !after) return false;
  return viewAngleDegrees(before->T_cw.linear(), after->T_cw.linear()) > max_degrees;
}

}  // namespace hiveslam::core
