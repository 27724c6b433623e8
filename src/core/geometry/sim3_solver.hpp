#pragma once
// The similarity between two keyframes' cameras from matched map points (3D-3D): RANSAC over
// minimal sets of three matches solved in closed form (Umeyama), inliers judged by reprojection
// in both images, then the closed form again on all inliers. refineSim3 (optim/) polishes it.
#include <cstdint>
#include <vector>

#include "core/frame/frame.hpp"
#include "core/geometry/sim3.hpp"

namespace hiveslam::core {

struct Sim3Match {
  Eigen::Vector3d p1, p2;   // the matched points in camera 1 and camera 2 coordinates
  Eigen::Vector2d uv1, uv2; // their keypoints (undistorted pixels)
  double sigma2_1 = 1, sigma2_2 = 1;  // squared pyramid-level scales of the keypoints
};

struct Sim3Result {
  bool found = false;
  Sim3 S12;                 // camera 2 -> camera 1
  std::vector<bool> inlier;
  int inliers = 0;
};

struct Sim3RansacOptions {
  int iterations = 300;
  int min_inliers = 20;
  double chi2 = 9.21;  // 99% of chi-square, 2 dof, per image
  bool fixed_scale = false;
  uint64_t seed = 1;
};

Sim3Result solveSim3Ransac(const Intrinsics& K1, const Intrinsics& K2, const std::vector<Sim3Match>& matches,
                           const Sim3RansacOptions& options = {});

// Inlier test of one match under S12 (reprojection in both images).
bool sim3Inlier(const Intrinsics& K1, const Intrinsics& K2, const Sim3Match& m, const Sim3& S12, double chi2);

// The scale the matched points themselves show under S12's rotation and translation: the
// median over the inliers of each point's ratio along its ray (p1 - t) . R p2 / |R p2|^2.
// Reprojections alone cannot tell it when the two cameras stand close together (a place seen
// again from where it was seen before): x -> s R x projects the same for every s.
double pointScale(const std::vector<Sim3Match>& matches, const Sim3& S12, const std::vector<bool>& inlier);

// The share of the inliers whose own ratio lies within `tolerance` (relative) of S12.s. A true
// place on a consistent map gives one ratio up to the points' depth noise; a median that only a
// few points agree with is not a scale the two maps share.
double pointScaleAgreement(const std::vector<Sim3Match>& matches, const Sim3& S12, const std::vector<bool>& inlier,
                           double tolerance);

}  // namespace hiveslam::core
