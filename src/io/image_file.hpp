#pragma once
#include <filesystem>
#include <opencv2/core.hpp>

namespace hiveslam::io {

// Reads an image as 8-bit grayscale. A missing, truncated or undecodable file throws
// InputError naming it; truncation is caught before decoding (PNG without its IEND chunk,
// JPEG without its end marker) because decoders otherwise return half an image.
cv::Mat readGrayImage(const std::filesystem::path& path);

}  // namespace hiveslam::io
