#pragma once
// The monocular gauge of a whole-map BA. Fixing the origin's pose fixes six of the seven
// degrees of freedom the reprojection error does not see; the seventh, the map's scale about
// the origin, is left free. Its gradient is zero, but the damped steps of Levenberg-Marquardt
// are not: once the trust region has grown, a step can carry a large move along the free
// direction with its real improvement (a lossy-link run ended with a map 80 times smaller than
// it began, and the frames posed on keyframes the correction could not rescale metres off).
// The solution is put back at the scale it started from, which changes no residual.
#include <vector>

#include <Eigen/Core>

#include "core/optim/bundle_adjustment.hpp"

namespace hiveslam::core {

// Camera centres of the problem's poses, in problem.poses order.
std::vector<Eigen::Vector3d> cameraCentres(const BaProblem& problem);

// For a problem with one fixed pose: scales the solved poses and points about that pose's
// centre so that the cameras are as far from it, in sum, as `centres_before` (taken before the
// solve) were. Returns the factor applied; 1 where not one pose is fixed (two or more hold the
// scale themselves) or there is no spread to measure.
double restoreScale(BaProblem& problem, const std::vector<Eigen::Vector3d>& centres_before);

}  // namespace hiveslam::core
