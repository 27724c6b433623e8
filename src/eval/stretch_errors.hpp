#pragma once
// Where in a run the error sits: the run cut into equal stretches of time, each with its mean
// position error under the one alignment of the whole run, and the scale of a Sim3 fitted to the
// stretch alone (reference metres per estimate unit). A monocular map with a steady scale gives
// the same scale in every stretch; drift changes it slowly, a young map rescaled in its first
// seconds shows a jump between the first stretches and the rest. Each stretch also says how far
// the camera turned over it, by the reference and by the estimate, and the angle between the
// two turns: a lens whose focal length is off turns every pan too far or not far enough, a view
// that mistakes a sideways step for a turn drifts in rotation where the reference barely turns.
#include <vector>

#include "eval/trajectory_error.hpp"

namespace hiveslam::eval {

struct Stretch {
  double from = 0, to = 0;  // seconds from the reference's first matched stamp
  size_t poses = 0;
  double mean_error = 0;    // metres, under the whole run's alignment
  double scale = 0;         // of the stretch's own Sim3 alignment; 0 with fewer than 3 poses
  // From the stretch's first pose to its last, in degrees: the rotation angle of the reference,
  // of the estimate, and of the one relative to the other (alignment does not change them).
  double turn = 0, turn_estimate = 0, turn_error = 0;
};

// `ate` as computeAte returns it. Throws InputError for fewer than 1 stretch.
std::vector<Stretch> stretchErrors(const AteResult& ate, int stretches);

}  // namespace hiveslam::eval
