#pragma once
// Observations measured again by patch alignment (remeasure_observations.hpp), kept by keyframe
// id and keypoint index until a global BA reads them. Only the node that made the keyframes holds
// their images: it measures, and the table travels to whichever node runs loop closing
// (distribution/wire: a Remeasured packet), where the final global BA of the run uses it.
//
// Kept as shifts from the detected, undistorted keypoint (Frame::points): a few tenths of a
// pixel, which is what the wire sends (1/256 px steps).
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
};

// By keyframe id; each keyframe's entries sorted by keypoint.
using Remeasurements = std::map<Id, std::vector<Remeasurement>>;

// Adds `from` to `into`, keyframe by keyframe: a keyframe's newer entries replace its older ones.
void mergeRemeasurements(Remeasurements& into, const Remeasurements& from);

// Replaces the `uv` of every observation of `mp` that `r` holds. Returns how many.
size_t applyRemeasurements(MapBaProblem& mp, const Remeasurements& r);

size_t remeasurementCount(const Remeasurements& r);

}  // namespace hiveslam::core
