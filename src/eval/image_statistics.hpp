#pragma once
// What a feature tracker sees in an image, as numbers that compare renders with real footage:
// FAST corners per frame (OpenCV's FAST, threshold 20, non-maximum suppression, on the image
// scaled to 640 pixels wide so that sizes compare), how they spread over an 8x6 grid (the share
// of cells holding one), the grey-level entropy and the mean gradient magnitude.
#include <opencv2/core.hpp>
#include <string>
#include <vector>

namespace hiveslam::eval {

struct ImageStatistics {
  double corners = 0;        // FAST corners
  double cells_covered = 0;  // share of the 8x6 cells with at least one corner, 0-1
  double entropy_bits = 0;   // of the grey-level histogram
  double gradient = 0;       // mean Sobel magnitude, grey levels per pixel
};

ImageStatistics imageStatistics(const cv::Mat& gray);

// The spread of one statistic over a sequence's frames.
struct Spread {
  double p10 = 0, median = 0, p90 = 0;
};
struct SequenceStatistics {
  size_t frames = 0;
  Spread corners, cells_covered, entropy_bits, gradient;
};
SequenceStatistics summarizeStatistics(const std::vector<ImageStatistics>& frames);

}  // namespace hiveslam::eval
