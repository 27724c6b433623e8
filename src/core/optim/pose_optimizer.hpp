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

// The robust loss of the first three rounds, on residuals in sigmas.
struct PoseLoss {
  // Huber at the inlier threshold (sqrt 5.991): tracking, where every frame is posed from its
  // predicted pose. Cauchy with a 1-sigma scale: a residual of e sigmas weighs 1/(1+e^2), so
  // observations a few sigmas out (a near point slightly misplaced) pull much less on a frame
  // whose other points lie mostly on one wall; SlamSystem::refineFrames. Replayed on three
  // blackout 3-node runs' refinements, the worst frame went from 18.5/11.0/23.1 mm
  // to 9.3/9.7/7.2 mm and the frames' RMS from 2.60/2.59/2.46 to 2.38/2.51/2.31 mm.
  enum class Kind { Huber, Cauchy } kind = Kind::Huber;
  double scale = 2.4477;  // sqrt(5.991)
  static PoseLoss cauchy(double scale = 1.0) { return {Kind::Cauchy, scale}; }
};

// Refines T_cw in place; `outlier` receives one flag per observation. Returns the inlier count.
int optimizePose(const Intrinsics& K, const std::vector<PoseObservation>& observations, Eigen::Isometry3d& T_cw,
                 std::vector<bool>& outlier, const PoseLoss& loss = {});

}  // namespace hiveslam::core
