#pragma once
// Finding and loading the bag-of-words vocabulary: the settings' `vocabulary` file, else the
// HIVESLAM_VOCABULARY environment variable, else the one shipped in the source tree
// (data/vocabulary/orb_k10_l4.bin).
#include <filesystem>
#include <memory>

#include "core/place/vocabulary.hpp"
#include "core/system/slam_settings.hpp"

namespace hiveslam::io {

std::filesystem::path vocabularyPath(const core::SlamSettings& settings);
// Throws InputError naming the file when it is missing or corrupt.
std::shared_ptr<const place::Vocabulary> loadVocabulary(const core::SlamSettings& settings);

}  // namespace hiveslam::io
