#pragma once
// Whether culling a keyframe would tear a gap in the map's keyframe chain. A monocular map carries
// its scale from keyframe to keyframe, and through a fast turn the chain is all that carries it.
// On sweep, a whole-map BA of 12 maps with the keyframes of 0.9 s of the U-turn left out (a gap of
// 25-50 degrees) raises the median keyframe ATE from 1.26 mm to 1.8-2.3 mm; the same cut on a
// straight stretch adds about 0.1 mm. A tail run's map had such a gap (22 degrees) where culling
// had taken two keyframes in a row. With a limit set, a
// redundant keyframe stays where its neighbours in time would be too far apart without it.
#include "core/map/keyframe.hpp"

namespace hiveslam::core {

// The angle in degrees between the optical axes of two camera rotations (R_cw: world to camera).
double viewAngleDegrees(const Eigen::Matrix3d& R_cw_a, const Eigen::Matrix3d& R_cw_b);

// Whether the optical axes of the neighbours of `k` are more than `max_degrees` apart (0: no
// limit). The neighbours are the nearest live keyframes before and after `k` in time among its
// covisible ones; without one on each side no gap is torn. The caller holds the map's mutex.
bool cullingLeavesGap(const KeyFrame& k, double max_degrees);

}  // namespace hiveslam::core
