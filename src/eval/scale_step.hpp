#pragma once
// The scale step of a monocular trajectory between two stretches of a run: each stretch is
// Sim3-aligned onto the reference on its own, and the step is the ratio of the two scales
// (1 when the map kept one scale; 1.01 when the second stretch came out 1% larger relative to
// the first). On an open path it is what a single ATE alignment cannot hide: a step of 1% at
// sweep's east turn costs about 15 mm of ATE.
#include <limits>

#include "eval/trajectory_error.hpp"

namespace hiveslam::eval {

struct StretchSplit {
  double before = 0.0;  // the first stretch: poses up to this many seconds after the first
  double after = 0.0;   // the second stretch: poses from this many seconds after the first
  // Optional outer bounds, for a path whose two ends are not the stretches to compare (a map
  // merged from two: blackout's east side against its west side).
  double first_from = -std::numeric_limits<double>::infinity();
  double second_until = std::numeric_limits<double>::infinity();
  bool inFirst(double t) const { return t >= first_from && t <= before; }
  bool inSecond(double t) const { return t >= after && t <= second_until; }
};

struct ScaleStep {
  // Each stretch's size relative to the reference (the inverse of its alignment's scale).
  double first_scale = 1.0, second_scale = 1.0;
  size_t first_poses = 0, second_poses = 0;
  double step() const { return second_scale / first_scale; }
};

// Times count from the estimate's first matched pose. Throws InputError when a stretch has
// fewer than 3 matched poses.
ScaleStep computeScaleStep(const io::Trajectory& ref, const io::Trajectory& est, const StretchSplit& split,
                           const MatchOptions& match = {});

}  // namespace hiveslam::eval
