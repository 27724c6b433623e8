#pragma once
// The cross-product matrix [v]x, so that skew(v) * w == v.cross(w): epipolar geometry and the
// Jacobians of rotations both need it.
#include <Eigen/Core>

namespace hiveslam::core {

inline Eigen::Matrix3d skew(const Eigen::Vector3d& v) {
  Eigen::Matrix3d m;
  m << 0, -v.z(), v.y(), v.z(), 0, -v.x(), -v.y(), v.x(), 0;
  return m;
}

}  // namespace hiveslam::core
