#pragma once
// Pairs poses of two trajectories the way evo does (`sync.associate_trajectories`): for each
// pose of the trajectory with fewer poses (the estimate when both have as many), take the
// pose of the other with the nearest stamp (the first one on a tie) and keep the pair if the
// stamps differ by at most max_diff. Not one-to-one, no interpolation.
#include <vector>

#include "io/trajectory.hpp"

namespace hiveslam::eval {

struct Association {
  std::vector<size_t> ref;  // indices into the reference trajectory
  std::vector<size_t> est;  // indices into the estimate, same length
  size_t size() const { return ref.size(); }
};

Association associateByTime(const io::Trajectory& ref, const io::Trajectory& est,
                            double max_diff = 0.01);
// KITTI files have no stamps: pose i pairs with pose i (both must have as many poses).
Association associateByIndex(const io::Trajectory& ref, const io::Trajectory& est);

}  // namespace hiveslam::eval
