#pragma once
// The pyramid levels of one grey image, built as the ORB extractor builds them (each level
// resized from level 0 with INTER_LINEAR, its size rounded), with the conversions between a
// level's pixels and level 0's. Patch alignment needs the very images the corners were found in.
#include <opencv2/core.hpp>
#include <vector>

namespace hiveslam::features {

class ImagePyramid {
 public:
  ImagePyramid() = default;
  ImagePyramid(const cv::Mat& gray, int levels, double scale_factor);

  int levels() const { return static_cast<int>(levels_.size()); }
  double scaleFactor() const { return scale_factor_; }
  const cv::Mat& level(int l) const { return levels_[static_cast<size_t>(l)]; }
  // Pixel centres map as cv::resize maps them: level pixel x sits at (x + 0.5) r - 0.5 on
  // level 0, r being the level's true size ratio (rounded sizes make it differ from the
  // nominal scale by up to 0.3%).
  cv::Point2d toLevel(int l, cv::Point2d level0) const;
  cv::Point2d toLevel0(int l, cv::Point2d at_level) const;

 private:
  std::vector<cv::Mat> levels_;
  std::vector<cv::Point2d> ratio_;  // level-0 size over level size, per axis
  double scale_factor_ = 1.0;
};

// The size of the pyramid level at `scale` (1 for level 0) of an image of size `level0`: the
// extractor's levels and ImagePyramid's must agree to the pixel.
inline cv::Size pyramidLevelSize(cv::Size level0, double scale) {
  return {cvRound(level0.width / scale), cvRound(level0.height / scale)};
}

// Bilinear sample of an 8-bit image at a sub-pixel position (pixel centres on integers), or
// NaN where the 2x2 neighbourhood leaves the image.
float sampleBilinear(const cv::Mat& gray, double x, double y);

}  // namespace hiveslam::features
