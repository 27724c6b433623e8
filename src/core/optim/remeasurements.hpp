#pragma once
// Observations measured again by patch alignment (remeasure_observations.hpp), kept by keyframe
// id and keypoint index until a global BA reads them. Only the node that made the keyframes holds
// their images: it measures, and the table travels to whichever node runs loop closing
// (distribution/wire: a Remeasured packet), where the final global BA of the run uses it.
//
// Kept as shifts from the detected, undistorted keypoint (Frame::points): a few tenths of a
// pixel, which is what the wire sends (1/256 px steps). Each shift moves its observation onto the
// texture location of its point's anchor (the point's observation in its first keyframe) as the
// measuring node's map had them; the node that applies it may hold a different map by then
// (points fused or replaced, an earlier observer added). So each entry names the point and the
// anchor it was measured for, and a shift is used only where both still hold: one point with
// observations of two texture locations bends the map as much as the corners do.
#include <Eigen/Core>
#include <cstdint>
#include <map>
#include <vector>

#include "core/map/ids.hpp"

namespace hiveslam::core {

struct MapBaProblem;

struct Remeasurement {
  uint32_t keypoint = 0;
  Eigen::Vector2f shift = Eigen::Vector2f::Zero();  // re-measured minus detected, pixels
  Id point = kNoId;                                 // the map point it was measured for
  Id anchor_keyframe = kNoId;                       // that point's anchor: keyframe and keypoint
  uint32_t anchor_keypoint = 0;
};

// By keyframe id; each keyframe's entries sorted by keypoint.
using Remeasurements = std::map<Id, std::vector<Remeasurement>>;

// Adds `from` to `into`, keyframe by keyframe: a keyframe's newer entries replace its older ones.
void mergeRemeasurements(Remeasurements& into, const Remeasurements& from);

struct RemeasurementUse {
  size_t applied = 0;        // observations given their re-measured uv
  size_t other_point = 0;    // left as found: the keypoint now belongs to another point
  size_t other_anchor = 0;   // left as found: the point's anchor is another observation here
  size_t not_measured = 0;   // neither an anchor nor in `r` (made after the measuring, or alignment failed)
};

// Replaces the `uv` of every observation of `mp` that `r` holds for the same point and anchor.
RemeasurementUse applyRemeasurements(MapBaProblem& mp, const Remeasurements& r);

// Each point's anchor in `mp`: the index of its observation in the earliest keyframe (lowest id).
std::vector<int> pointAnchors(const MapBaProblem& mp);

size_t remeasurementCount(const Remeasurements& r);

}  // namespace hiveslam::core
