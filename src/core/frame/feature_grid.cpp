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
      cells_(static_cast<size_t>(kCols * kRows)) {
  for (int i = 0; i < static_cast<int>(points.size()); ++i) {
    const auto& p = points[static_cast<size_t>(i)];
    cells_[static_cast<size_t>(cellY(p.y()) * kCols + cellX(p.x()))].push_back(i);
  }
}

int FeatureGrid::cellX(double x) const { return std::clamp(static_cast<int>(std::floor((x - min_x_) * inv_w_)), 0, kCols - 1); }
int FeatureGrid::cellY(double y) const { return std::clamp(static_cast<int>(std::floor((y - min_y_) * inv_h_)), 0, kRows - 1); }

std::vector<int> FeatureGrid::inRadius(const std::vector<Eigen::Vector2d>& points, double x, double y,
                                       double radius) const {
  std::vector<int> out;
  if (cells_.empty()) return out;
  const int x0 = cellX(x - radius), x1 = cellX(x + radius), y0 = cellY(y - radius), y1 = cellY(y + radius);
  const double r2 = radius * radius;
  for (int cy = y0; cy <= y1; ++cy)
    for (int cx = x0; cx <= x1; ++cx)
      for (int i : cells_[static_cast<size_t>(cy * kCols + cx)]) {
        const auto& p = points[static_cast<size_t>(i)];
        if ((p.x() - x) * (p.x() - x) + (p.y() - y) * (p.y() - y) <= r2) out.push_back(i);
      }
  return out;
}

}  // namespace hiveslam::core
