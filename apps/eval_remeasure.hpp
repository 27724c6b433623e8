#pragma once
// hiveslam eval remeasure ATLAS DATASET: what patch-aligned observations would do to a saved map.
#include <memory>
#include <string>

#include "core/map/map.hpp"
#include "eval/scale_step.hpp"

namespace hiveslam::apps {

// Bundle-adjusts the whole map twice, on its detected corners and on its observations measured
// again by patch alignment in the dataset's images (core/optim/remeasure_observations), and
// prints each result's keyframe ATE and scale step against the dataset's ground truth.
void evalRemeasure(const std::shared_ptr<core::Map>& map, const std::string& dataset, const eval::StretchSplit& split);

}  // namespace hiveslam::apps
