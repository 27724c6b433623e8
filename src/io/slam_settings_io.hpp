#pragma once
#include <filesystem>
#include <string>
#include <vector>

#include "communication/dds/dds_options.hpp"
#include "core/system/slam_settings.hpp"
#include "distribution/distribution_settings.hpp"
#include "viz/view_settings.hpp"

namespace hiveslam::io {

// Every key a settings file may hold, by section: "camera.model", "slam.orb.features",
// "distribution.global_batch", "dds.heartbeat_ms", ... (docs/SETTINGS.md lists each).
std::vector<std::string> settingKeys();

// Applies the `slam:` section of a settings YAML over `settings` (keys as in SlamSettings, ORB
// options under `slam: orb:`). Unknown keys are an error naming the file: a typo must not
// silently fall back to a default.
void applySlamSettings(const std::filesystem::path& file, core::SlamSettings& settings);

// Applies the `distribution:` section (keys as in DistributionSettings), checked the same way
// and for ranges.
void applyDistributionSettings(const std::filesystem::path& file, distribution::DistributionSettings& settings);

// Applies the `dds:` section (max_datagram_bytes, heartbeat_ms, history_depth), checked the
// same way and for ranges. The domain comes from the command line.
void applyDdsSettings(const std::filesystem::path& file, communication::DdsOptions& options);

// Applies the `view:` section (the live view's rates and web budget, viz::ViewSettings).
void applyViewSettings(const std::filesystem::path& file, viz::ViewSettings& settings);

}  // namespace hiveslam::io
