#pragma once
// Matching by projection: map points are projected with a predicted pose and matched to the
// keypoints near their projection, within a window scaled by the pyramid level (tracking from
// the last frame, tracking the local map, fusing duplicates).
#include <Eigen/Geometry>
#include <memory>
#include <vector>

#include "core/frame/frame.hpp"
#include "core/map/map_point.hpp"

namespace hiveslam::core {

constexpr int kMatchHigh = 100;  // Hamming threshold for matches by projection
constexpr int kMatchLow = 50;    // for matches without a geometric prior

using PointSlots = std::vector<std::shared_ptr<MapPoint>>;  // one per keypoint

// Projects the points of the last frame with T_cw and fills free slots of `current`. radius in
// pixels at level 0. Returns the number of new matches.
int matchFromLastFrame(const Frame& current, const Eigen::Isometry3d& T_cw, PointSlots& current_points,
                       const Frame& last, const PointSlots& last_points, const std::vector<bool>& last_outliers,
                       double radius, const std::vector<double>& scales, bool check_rotation);

// Projects candidate map points (already matched ones are skipped) into the frame, counting
// those in view (MapPoint::visible); radius_factor multiplies the level-scaled window.
int matchLocalMap(const Frame& frame, const Eigen::Isometry3d& T_cw, PointSlots& points,
                  const std::vector<std::shared_ptr<MapPoint>>& candidates, double radius_factor,
                  const std::vector<double>& scales);

// Keypoint of `frame` (within `radius` of uv, octave in [min_level, max_level]) whose
// descriptor is closest to `descriptor`; -1 if none is within max_distance.
int bestNear(const Frame& frame, const Eigen::Vector2d& uv, double radius, int min_level, int max_level,
             const unsigned char* descriptor, int max_distance, int* distance = nullptr);

}  // namespace hiveslam::core
