#pragma once
// Duplicate fusion: map points projected into a keyframe merge with the keypoint found there,
// as a new observation or, when the keypoint already has a point, by fusing the two (the one
// with more observations survives). Local mapping fuses a new keyframe with its neighbours;
// loop closing and map merging fuse the two sides of the seam.
#include <memory>
#include <vector>

#include "core/map/map.hpp"

namespace hiveslam::core {

// `points` is a copy: fusing rewrites keyframe slots, possibly the very vector it came from.
// Returns the number of points fused or added. The caller holds the map's mutex.
int fusePoints(Map& map, KeyFrame& kf, std::vector<std::shared_ptr<MapPoint>> points,
               const std::vector<double>& scales);

}  // namespace hiveslam::core
