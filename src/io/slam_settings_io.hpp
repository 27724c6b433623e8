#pragma once
#include <filesystem>

#include "core/system/slam_settings.hpp"

namespace hiveslam::io {

// Applies the `slam:` section of a settings YAML over `settings` (keys as in SlamSettings, ORB
// options under `slam: orb:`). Unknown keys are an error naming the file: a typo must not
// silently fall back to a default.
void applySlamSettings(const std::filesystem::path& file, core::SlamSettings& settings);

}  // namespace hiveslam::io
