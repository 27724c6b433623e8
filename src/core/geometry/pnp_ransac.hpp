#pragma once
// The camera pose from 2D-3D matches with outliers (relocalization): OpenCV's USAC PnP.
#include <Eigen/Geometry>
#include <optional>
#include <vector>

#include "core/frame/frame.hpp"

namespace hiveslam::core {

struct PnpMatch {
  Eigen::Vector3d p_w;  // map point
  Eigen::Vector2d uv;   // undistorted pixel
};

struct PnpResult {
  Eigen::Isometry3d T_cw = Eigen::Isometry3d::Identity();
  std::vector<int> inliers;  // indices into the matches
};

// Null when no pose has at least `min_inliers` matches within `threshold_px`. Most calls are
// for the wrong place: OpenCV's classic RANSAC spent its 300 iterations on each (12 ms for 30
// matches, 11 of them right, on this machine); USAC rejects a bad model early and finds the same
// poses in 1-2 ms (bench/core_bench.cpp, PnpRansac).
std::optional<PnpResult> solvePnpRansac(const Intrinsics& K, const std::vector<PnpMatch>& matches, double threshold_px,
                                        int min_inliers, int seed);

}  // namespace hiveslam::core
