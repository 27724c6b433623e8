#pragma once
// A whole map as one bundle-adjustment problem: every live keyframe (the map's origin fixed)
// and every point seen by at least two of them, each observation weighted by its pyramid
// level. Global BA solves it; eval/scale_precision perturbs and solves it again.
#include <vector>

#include "core/map/map.hpp"
#include "core/optim/bundle_adjustment.hpp"

namespace hiveslam::core {

struct MapBaProblem {
  BaProblem problem;
  std::vector<KeyFrame*> keyframes;  // problem.poses order, by id
  std::vector<MapPoint*> points;     // problem.points order, by id
  // Per observation (problem.observations order): the keyframe and its keypoint index.
  std::vector<std::pair<KeyFrame*, int>> sources;
};

// The caller holds map.mutex. `level_scales`: the scale of each pyramid level.
MapBaProblem buildMapBaProblem(const Map& map, const std::vector<double>& level_scales);

}  // namespace hiveslam::core
