#pragma once
// Nonlinear refinement of a keyframe-to-keyframe similarity: the reprojection error of the
// matched points of camera 2 in image 1 and of camera 1 in image 2 (points held fixed), Huber
// kernel, then once more without the matches the first round rejects.
#include <vector>

#include "core/geometry/sim3_solver.hpp"

namespace hiveslam::core {

// Refines S12 in place over the matches flagged in `inlier` (updated); returns the inliers.
int refineSim3(const Intrinsics& K1, const Intrinsics& K2, const std::vector<Sim3Match>& matches, Sim3& S12,
               std::vector<bool>& inlier, bool fixed_scale = false, double chi2 = 10.0);

}  // namespace hiveslam::core
