#pragma once
// hiveslam eval lens ATLAS CAMERA: the lens a saved map says it was seen with.
#include <memory>
#include <string>

#include "core/map/map.hpp"

namespace hiveslam::apps {

// Refines the lens of `camera_file` (the calibration the run was given: a settings YAML,
// sensor.yaml or calib.txt) against the map's own keypoints (core/optim/lens_refinement) and
// prints both; for a sequence hiveslam synth rendered (`dataset`, optional), the lens its images
// were made with too. With `write`, the refined lens goes to that settings file's `camera:`
// section, for `run --config`.
void evalLens(const std::shared_ptr<core::Map>& map, const std::string& camera_file, const std::string& dataset,
              const std::string& write = {});

}  // namespace hiveslam::apps
