#include "core/frame/feature_grid.hpp"

#include <algorithm>
#include <cmath>

namespace hiveslam::core {

FeatureGrid::FeatureGrid(const std::vector<Eigen::Vector2d>& points, double min_x, double min_y, double max_x,
                         double max_y)
    : min_x_(min_x),
      min_y_(min_y),
      inv_w_(kCols / std::max(max_x - min_x, 1.0)),
      inv_h_(kRows / std::max(max_y - min_y, 1.0)),
      start_(static_cast<size_t>(kCols * kRows + 1), 0),
      index_(points.size()) {
  // Counting sort by cell: a stable grouping, so each cell lists its points in index order.
  std::vector<int> cell_of(points.size());
  if (!points.empty()) {
    lo_x_ = hi_x_ = points[0].x();
    lo_y_ = hi_y_ = points[0].y();
  }
  for (size_t i = 0; i < points.size(); ++i) {
    lo_x_ = std::min(lo_x_, points[i].x());
    hi_x_ = std::max(hi_x_, points[i].x());
    lo_y_ = std::min(lo_y_, points[i].y());
    hi_y_ = std::max(hi_y_, points[i].y());
    cell_of[i] = cellY(points[i].y()) * kCols + cellX(points[i].x());
    ++start_[static_cast<size_t>(cell_of[i]) + 1];
  }
  for (size_t c = 1; c < start_.size(); ++c) start_[c] += start_[c - 1];
  std::vector<int> fill(start_.begin(), start_.end() - 1);
  for (size_t i = 0; i < points.size(); ++i)
    index_[static_cast<size_t>(fill[static_cast<size_t>(cell_of[i])]++)] = static_cast<int>(i);
}


}  // namespace hiveslam::core
