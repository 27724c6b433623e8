#pragma once
// hiveslam eval remeasure ATLAS DATASET: what patch-aligned observations would do to a saved map.
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "core/map/map.hpp"
#include "eval/scale_step.hpp"

namespace hiveslam::apps {

// Bundle-adjusts the whole map twice, on its detected corners and on its observations measured
// again by patch alignment in the dataset's images (core/optim/remeasure_observations), and
// prints each result's keyframe ATE and scale step against the dataset's ground truth. Each of
// `leave_out` (seconds from the first keyframe, from and to) then solves the re-measured map
// again without the observations of its keyframes: a gap in the keyframe chain, as culling makes.
void evalRemeasure(const std::shared_ptr<core::Map>& map, const std::string& dataset, const eval::StretchSplit& split,
                   const std::vector<std::pair<double, double>>& leave_out = {});

}  // namespace hiveslam::apps
