#pragma once
// A uniform grid over the undistorted image that answers "which keypoints lie within r pixels
// of (x, y)" without scanning them all: matching by projection asks it thousands of times per
// frame. Stored compactly (one index array sorted by cell, and each cell's start in it), so
// building, copying and querying a grid allocate nothing per cell or per query.
#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <vector>

namespace hiveslam::core {

class FeatureGrid {
 public:
  FeatureGrid() = default;
  // Bounds of the undistorted keypoints (they can leave the image under strong distortion).
  FeatureGrid(const std::vector<Eigen::Vector2d>& points, double min_x, double min_y, double max_x, double max_y);

  // Calls f(i) for the index of every point in the cells that the band within `half_width`
  // pixels of the segment p0-p1 passes through: a superset of the points in the band, which the
  // caller tests itself. The band is walked row by row of cells (column by column for a segment
  // closer to horizontal), so each cell is visited once.
  template <class F>
  void forEachNearSegment(const Eigen::Vector2d& p0, const Eigen::Vector2d& p1, double half_width, F&& f) const {
    if (start_.empty() || index_.empty()) return;
    const Eigen::Vector2d d = p1 - p0;
    const bool by_rows = std::abs(d.y()) >= std::abs(d.x());
    // In the walked frame: `along` is the walked axis (y for rows), `across` the other.
    const double a0 = by_rows ? p0.y() : p0.x(), a1 = by_rows ? p1.y() : p1.x();
    const double c0 = by_rows ? p0.x() : p0.y(), c1 = by_rows ? p1.x() : p1.y();
    const double seg_lo = std::min(a0, a1) - half_width, seg_hi = std::max(a0, a1) + half_width;
    const double slope = a1 != a0 ? (c1 - c0) / (a1 - a0) : 0.0;  // across per along
    // Half the band's width across, measured along the across axis.
    const double spread = half_width * std::sqrt(1.0 + slope * slope);
    const int cells = by_rows ? kRows : kCols;
    const double origin = by_rows ? min_y_ : min_x_, size = 1.0 / (by_rows ? inv_h_ : inv_w_);
    // The edge rows (columns) also hold the points beyond the grid's bounds.
    const double lo_all = by_rows ? lo_y_ : lo_x_, hi_all = by_rows ? hi_y_ : hi_x_;
    const double across_lo = by_rows ? lo_x_ : lo_y_, across_hi = by_rows ? hi_x_ : hi_y_;
    const double a_min = std::min(a0, a1), a_max = std::max(a0, a1);
    for (int k = 0; k < cells; ++k) {
      double lo = origin + k * size, hi = lo + size;
      if (k == 0) lo = std::min(lo, lo_all);
      if (k == cells - 1) hi = std::max(hi, hi_all);
      lo = std::max(lo, seg_lo);
      hi = std::min(hi, seg_hi);
      if (lo > hi) continue;
      // The segment's across coordinates over [lo, hi], clamped to its own ends.
      const double u0 = c0 + slope * (std::clamp(lo, a_min, a_max) - a0);
      const double u1 = c0 + slope * (std::clamp(hi, a_min, a_max) - a0);
      const double from = std::min(u0, u1) - spread, to = std::max(u0, u1) + spread;
      if (to < across_lo || from > across_hi) continue;
      const int q0 = by_rows ? cellX(from) : cellY(from), q1 = by_rows ? cellX(to) : cellY(to);
      for (int q = q0; q <= q1; ++q) {
        const size_t cell = static_cast<size_t>(by_rows ? k * kCols + q : q * kCols + k);
        for (int m = start_[cell]; m < start_[cell + 1]; ++m) f(index_[static_cast<size_t>(m)]);
      }
    }
  }

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
  double lo_x_ = 0, hi_x_ = 0, lo_y_ = 0, hi_y_ = 0;  // the points' own extent
  std::vector<int> start_;  // kCols * kRows + 1 offsets into index_
  std::vector<int> index_;  // point indices grouped by cell
  // Clamped before the cast: a double beyond int's range (or not a number) cast to int is
  // undefined (fuzz/wire_fuzzer reached it with a point at -1.6e28 in a received keyframe).
  static int cell(double c, int cells) { return c >= 0 ? (c < cells ? static_cast<int>(c) : cells - 1) : 0; }
  int cellX(double x) const { return cell(std::floor((x - min_x_) * inv_w_), kCols); }
  int cellY(double y) const { return cell(std::floor((y - min_y_) * inv_h_), kRows); }
};

}  // namespace hiveslam::core
