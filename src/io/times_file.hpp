#pragma once
#include <filesystem>
#include <vector>

namespace hiveslam::io {

// A times file: one timestamp in seconds per line (first field), strictly increasing.
// Throws InputError naming the file and line of the first bad entry.
std::vector<double> readTimesFile(const std::filesystem::path& path);

}  // namespace hiveslam::io
