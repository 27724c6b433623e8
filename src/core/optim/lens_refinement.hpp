#pragma once
// The lens a map was made with, estimated from the map itself: a bundle adjustment over the
// keyframe poses, the points and one shared pinhole lens with a radial term (fx, fy, cx, cy, k1),
// on the keypoints where the detector found them. A camera's nominal calibration is often off by
// a few percent in focal length and carries an unstated radial distortion; the realistic renders
// halve their median error in real time when given the true lens (docs/BENCHMARKS.md).
#include "core/optim/bundle_adjustment.hpp"
#include "core/optim/map_ba_problem.hpp"

namespace hiveslam::core {

// x_d = x (1 + k1 r^2) on normalized coordinates, then u = fx x_d + cx (PinholeRadTan's k1).
struct LensParameters {
  double fx = 0, fy = 0, cx = 0, cy = 0, k1 = 0;
};

struct LensRefinement {
  LensParameters lens;
  int observations = 0;         // used (points seen by at least min_observations keyframes)
  int outliers = 0;             // left out of the second round
  double rms_before_px = 0;     // level-weighted reprojection error with the starting lens
  double rms_after_px = 0;      // and with the refined one, inliers only
  bool converged = false;
};

struct LensRefinementOptions {
  int min_observations = 3;
  int iterations = 50;
};

// `problem`'s observations must be the keypoints as detected (rawObservations), its poses and
// points a map made with `start`. The two lowest poses with observations are held (the gauge:
// position, rotation and scale); the problem is not changed.
LensRefinement refineLens(const BaProblem& problem, const LensParameters& start, const LensRefinementOptions& options = {});

// A map's problem with each observation where the detector found the keypoint, not where the
// nominal lens undistorts it to.
BaProblem rawObservations(const MapBaProblem& map);

}  // namespace hiveslam::core
