#pragma once
// Saving and loading an atlas (every map: keyframes with their features and poses, map points
// with their observations, the spanning tree and loop links) to a versioned binary file, so that
// a map built once can be localized against later. Covisibility and bags of words are rebuilt on
// load; culled keyframes are not saved (they only anchor the frames of the run that made them).
//
// Format, little endian: "HSATLAS\0" | u32 version (1) | u32 maps | per map: u64 id, u64 origin,
// u32 keyframes, u32 points, then the keyframes and points (see atlas_file.cpp for the fields).
#include <filesystem>
#include <memory>
#include <vector>

#include "core/map/map.hpp"
#include "core/place/vocabulary.hpp"

namespace hiveslam::io {

// Takes each map's mutex while writing it.
void saveAtlas(const std::filesystem::path& file, const std::vector<std::shared_ptr<core::Map>>& maps);
// Throws InputError (one line) on a missing, truncated, corrupt or newer-version file. With a
// vocabulary, each keyframe gets its bag of words again.
std::vector<std::shared_ptr<core::Map>> loadAtlas(const std::filesystem::path& file,
                                                  const place::Vocabulary* vocabulary = nullptr);

}  // namespace hiveslam::io
