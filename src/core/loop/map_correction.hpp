#pragma once
// Moving a map to corrected keyframe poses (after an essential graph or a global BA): each
// keyframe's correction C = S_new^-1 * S_old carries the points it anchors; keyframes the
// optimization did not see (created meanwhile) inherit the correction of their nearest ancestor
// in the spanning tree (without a parent yet: of the keyframe tracking posed them from; culled:
// of their anchor; the root of a map merged into this one: of its strongest neighbour). Rigid
// poses that come with moved points get the scale change their points show. Each keyframe's
// scale_change takes its correction's scale, so culled keyframes and tracked frames, held
// relative to live keyframes (KeyFrame::pose), follow it exactly. A point that no keyframe
// sees and the correction does not place has nothing to follow: it is erased. The caller holds
// the map's mutex.
#include <unordered_map>

#include "core/geometry/sim3.hpp"
#include "core/map/map.hpp"

namespace hiveslam::core {

struct PoseCorrection {
  std::unordered_map<KeyFrame*, Sim3> before, after;  // S_iw of the optimized keyframes
  // Optimized point positions (global BA); others move with their anchor keyframe.
  std::unordered_map<MapPoint*, Eigen::Vector3d> points;
};

void applyCorrection(Map& map, const PoseCorrection& correction, const std::vector<double>& scales);

}  // namespace hiveslam::core
