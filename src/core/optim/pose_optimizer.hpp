#pragma once
// Pose-only optimization of one frame against fixed map points: four rounds of robust
// least squares, each re-classifying observations as inliers (chi-square <= 5.991) or outliers,
// so injected wrong matches are rejected rather than averaged in.
#include <Eigen/Geometry>
#include <vector>

#include "core/frame/frame.hpp"

namespace hiveslam::core {

struct PoseObservation {
  Eigen::Vector3d point;  // world
  Eigen::Vector2d uv;     // undistorted pixel
  double inv_sigma = 1.0;
};

// Refines T_cw in place; `outlier` receives one flag per observation. Returns the inlier count.
int optimizePose(const Intrinsics& K, const std::vector<PoseObservation>& observations, Eigen::Isometry3d& T_cw,
                 std::vector<bool>& outlier);

}  // namespace hiveslam::core
