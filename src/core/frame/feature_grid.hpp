#pragma once
// A uniform grid over the undistorted image that answers "which keypoints lie within r pixels
// of (x, y)" without scanning them all: matching by projection asks it thousands of times per
// frame. Stored compactly (one index array sorted by cell, and each cell's start in it), so
// building, copying and querying a grid allocate nothing per cell or per query.
#include <Eigen/Core>
#include <vector>

namespace hiveslam::core {

class FeatureGrid {
 public:
  FeatureGrid() = default;
  // Bounds of the undistorted keypoints (they can leave the image under strong distortion).
  FeatureGrid(const std::vector<Eigen::Vector2d>& points, double min_x, double min_y, double max_x, double max_y);

  // Calls f(i) for the index of each point within `radius` of (x, y), cell by cell and in
  // increasing index within a cell; `points` are the ones the grid was built on (passed again
  // so that a grid can be copied and moved with its frame).
  template <class F>
  void forEachInRadius(const std::vector<Eigen::Vector2d>& points, double x, double y, double radius, F&& f) const {
    if (start_.empty()) return;
    const int x0 = cellX(x - radius), x1 = cellX(x + radius), y0 = cellY(y - radius), y1 = cellY(y + radius);
    const double r2 = radius * radius;
    for (int cy = y0; cy <= y1; ++cy)
      for (int cx = x0; cx <= x1; ++cx) {
        const size_t cell = static_cast<size_t>(cy * kCols + cx);
        for (int k = start_[cell]; k < start_[cell + 1]; ++k) {
          const int i = index_[static_cast<size_t>(k)];
          const auto& p = points[static_cast<size_t>(i)];
          if ((p.x() - x) * (p.x() - x) + (p.y() - y) * (p.y() - y) <= r2) f(i);
        }
      }
  }

 private:
  static constexpr int kCols = 64, kRows = 48;
  double min_x_ = 0, min_y_ = 0, inv_w_ = 1, inv_h_ = 1;
  std::vector<int> start_;  // kCols * kRows + 1 offsets into index_
  std::vector<int> index_;  // point indices grouped by cell
  int cellX(double x) const;
  int cellY(double y) const;
};

}  // namespace hiveslam::core
