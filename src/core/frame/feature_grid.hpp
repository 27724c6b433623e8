#pragma once
// A uniform grid over the undistorted image that answers "which keypoints lie within r pixels
// of (x, y)" without scanning them all: matching by projection asks it thousands of times per
// frame.
#include <Eigen/Core>
#include <vector>

namespace hiveslam::core {

class FeatureGrid {
 public:
  FeatureGrid() = default;
  // Bounds of the undistorted keypoints (they can leave the image under strong distortion).
  FeatureGrid(const std::vector<Eigen::Vector2d>& points, double min_x, double min_y, double max_x, double max_y);

  // Indices of points within `radius` of (x, y); `points` are the ones the grid was built on
  // (passed again so that a grid can be copied and moved with its frame).
  std::vector<int> inRadius(const std::vector<Eigen::Vector2d>& points, double x, double y, double radius) const;

 private:
  static constexpr int kCols = 64, kRows = 48;
  double min_x_ = 0, min_y_ = 0, inv_w_ = 1, inv_h_ = 1;
  std::vector<std::vector<int>> cells_;
  int cellX(double x) const;
  int cellY(double y) const;
};

}  // namespace hiveslam::core
