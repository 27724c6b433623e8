#pragma once
// How precisely a map's own measurements fix its scale from one stretch of the run to another.
//
// The map's solution is taken as the truth: every observation is replaced by the exact
// projection of its point, Gaussian noise of the measured size (per coordinate, in units of
// the observation's pyramid-level sigma) is added, the whole map is bundle-adjusted again, and
// the scale step between the two stretches (eval/scale_step) is read off the keyframe centres.
// The spread of the step over the trials is what any estimator using these associations can
// reach: a map that holds the step to 0.4% cannot give runs whose steps agree to 0.1%.
#include <cstdint>
#include <vector>

#include "core/optim/bundle_adjustment.hpp"
#include "eval/scale_step.hpp"

namespace hiveslam::eval {

struct ScalePrecisionOptions {
  StretchSplit split;  // seconds from the first keyframe
  double noise = 0.0;  // per coordinate, in level sigmas; 0: the residual noise of the map
  int trials = 10;
  int iterations = 30;
  uint64_t seed = 1;
};

struct ScalePrecision {
  size_t keyframes = 0, points = 0, observations = 0;
  size_t first_keyframes = 0, second_keyframes = 0;
  double residual_noise = 0.0;  // the map's residual RMS per coordinate, in level sigmas
  double noise = 0.0;           // what the trials added
  std::vector<double> steps;    // one per trial
  double mean = 1.0, sd = 0.0;
};

// RMS of the residuals per coordinate in units of each observation's sigma, over those under
// the 95% chi-square bound, divided by the degrees of freedom left after fitting every point
// and free pose (so an exact fit of noisy data gives back the noise).
double residualNoise(const core::BaProblem& problem);

// `stamps`: each pose's time stamp, in problem.poses order. Throws InputError when a stretch
// has fewer than 3 keyframes.
ScalePrecision computeScalePrecision(const core::BaProblem& problem, const std::vector<double>& stamps,
                                     const ScalePrecisionOptions& options);

}  // namespace hiveslam::eval
