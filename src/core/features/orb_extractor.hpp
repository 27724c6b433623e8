#pragma once
// ORB features (Rublee et al. 2011, with the spatially uniform selection of ORB-SLAM): a scale
// pyramid, FAST corners over each level with a lower threshold retried in the grid cells that
// found none, a quadtree that keeps the strongest corner of each region, intensity-centroid
// orientation and 256-bit rotated BRIEF descriptors over a smoothed image; optionally each
// corner placed between pixels.
#include <opencv2/core.hpp>
#include <vector>

namespace hiveslam::features {

struct OrbOptions {
  int features = 1000;
  double scale_factor = 1.2;
  int levels = 8;
  int fast_threshold = 20;      // first try in each cell
  int min_fast_threshold = 7;   // retry in cells where the first found nothing
  int cell_size = 32;           // pixels, FAST grid cell
  // Place each corner between pixels (the Harris peak, core/features/corner_refinement): on
  // rendered views a measurement 3x more precise than the FAST pixel, for about 0.7 ms a frame;
  // the synthetic suite's median ATE 9-41% lower. On the real KITTI 07 excerpt, 0 tracking
  // losses in 56 runs either way and a 3% higher median ATE.
  bool subpixel = true;
};

// A corner found only at min_fast_threshold, in a cell where fast_threshold found none, carries
// this class_id (the others -1). On plain walls these are the image noise's, and on the
// realistic suite two of three wrong new points come from them (docs/BENCHMARKS.md).
constexpr int kWeakCorner = 1;
inline bool isWeakCorner(const cv::KeyPoint& k) { return k.class_id == kWeakCorner; }

class OrbExtractor {
 public:
  explicit OrbExtractor(const OrbOptions& options = {});

  // Keypoints in level-0 pixel coordinates (octave = pyramid level, size = patch diameter at
  // that level, angle in degrees) and one 32-byte descriptor row per keypoint.
  void extract(const cv::Mat& gray, std::vector<cv::KeyPoint>& keypoints, cv::Mat& descriptors) const;

  const OrbOptions& options() const { return options_; }
  double scale(int level) const { return scales_[static_cast<size_t>(level)]; }
  // Scale factor squared per level: the variance of a measurement made at that level.
  double sigma2(int level) const { return scales_[static_cast<size_t>(level)] * scales_[static_cast<size_t>(level)]; }
  const std::vector<double>& scales() const { return scales_; }

 private:
  OrbOptions options_;
  std::vector<double> scales_;
  std::vector<int> per_level_;
};

}  // namespace hiveslam::features
