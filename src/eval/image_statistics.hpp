#pragma once
// What a feature tracker sees in an image, as numbers that compare renders with real footage:
// FAST corners per frame (OpenCV's FAST, threshold 20, non-maximum suppression, on the image
// scaled to 640 pixels wide so that sizes compare), how they spread over an 8x6 grid (the share
// of cells holding one), weak corners (FAST at threshold 7 in the 32-pixel cells that hold none at
// 20: what ORB-SLAM's extractor, and ours, take when a cell is bare), the grey-level entropy, the
// mean gradient magnitude, and how much of the image repeats itself (common/look_alikes.hpp).
#include <opencv2/core.hpp>
#include <string>
#include <vector>

namespace hiveslam::eval {

struct ImageStatistics {
  double corners = 0;        // FAST corners
  double cells_covered = 0;  // share of the 8x6 cells with at least one corner, 0-1
  double weak_corners = 0;   // FAST corners at threshold 7 in 32-pixel cells without one at 20
  double entropy_bits = 0;   // of the grey-level histogram
  double gradient = 0;       // mean Sobel magnitude, grey levels per pixel
  double look_alikes = 0;    // share of ORB features with a look-alike elsewhere in the image, 0-1
};

ImageStatistics imageStatistics(const cv::Mat& gray);

// The spread of one statistic over a sequence's frames.
struct Spread {
  double p10 = 0, median = 0, p90 = 0;
};
struct SequenceStatistics {
  size_t frames = 0;
  Spread corners, cells_covered, weak_corners, entropy_bits, gradient, look_alikes;
};
SequenceStatistics summarizeStatistics(const std::vector<ImageStatistics>& frames);

}  // namespace hiveslam::eval
