#pragma once
#include <cstddef>
#include <cstdint>
#include <optional>
#include <opencv2/core.hpp>

namespace hiveslam::io {

// The fast path for the one PNG layout camera datasets use (EuRoC, KITTI, ours): 8-bit
// grayscale, not interlaced. The whole IDAT stream is inflated in one call by libdeflate, which
// inflates about twice as fast as zlib's streaming decoder under libpng; PNG decoding was a
// quarter of the tracking thread's time. Returns nullopt for any other layout (the caller falls
// back to OpenCV's decoder); throws std::runtime_error for a corrupt file of this layout.
std::optional<cv::Mat> decodeGrayPng(const uint8_t* data, size_t size);

}  // namespace hiveslam::io
