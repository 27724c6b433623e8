#include "eval/image_statistics.hpp"

#include <algorithm>
#include <cmath>
#include <opencv2/features2d.hpp>
#include <opencv2/imgproc.hpp>

#include "common/look_alikes.hpp"

namespace hiveslam::eval {

ImageStatistics imageStatistics(const cv::Mat& gray_in) {
  cv::Mat gray = gray_in;
  if (gray.cols != 640) cv::resize(gray_in, gray, {}, 640.0 / gray_in.cols, 640.0 / gray_in.cols, cv::INTER_AREA);
  ImageStatistics s;
  std::vector<cv::KeyPoint> corners;
  cv::FAST(gray, corners, 20, true);
  s.corners = static_cast<double>(corners.size());
  constexpr int kCols = 8, kRows = 6;
  bool covered[kRows][kCols] = {};
  for (const auto& k : corners)
    covered[std::min(kRows - 1, static_cast<int>(k.pt.y * kRows / gray.rows))]
           [std::min(kCols - 1, static_cast<int>(k.pt.x * kCols / gray.cols))] = true;
  int n = 0;
  for (const auto& row : covered) n += static_cast<int>(std::count(std::begin(row), std::end(row), true));
  s.cells_covered = static_cast<double>(n) / (kRows * kCols);
  constexpr int kCell = 32;
  const int cell_cols = (gray.cols + kCell - 1) / kCell;
  std::vector<uint8_t> strong(static_cast<size_t>(cell_cols * ((gray.rows + kCell - 1) / kCell)), 0);
  auto cell = [&](const cv::KeyPoint& k) {
    return static_cast<size_t>(static_cast<int>(k.pt.y) / kCell * cell_cols + static_cast<int>(k.pt.x) / kCell);
  };
  for (const auto& k : corners) strong[cell(k)] = 1;
  std::vector<cv::KeyPoint> weak;
  cv::FAST(gray, weak, 7, true);
  s.weak_corners = static_cast<double>(std::count_if(weak.begin(), weak.end(), [&](const cv::KeyPoint& k) { return !strong[cell(k)]; }));
  std::vector<double> histogram(256, 0.0);
  for (int y = 0; y < gray.rows; ++y)
    for (int x = 0; x < gray.cols; ++x) histogram[gray.at<uchar>(y, x)] += 1;
  const double total = static_cast<double>(gray.total());
  for (double h : histogram)
    if (h > 0) s.entropy_bits -= h / total * std::log2(h / total);
  cv::Mat gx, gy, magnitude;
  cv::Sobel(gray, gx, CV_32F, 1, 0);
  cv::Sobel(gray, gy, CV_32F, 0, 1);
  cv::magnitude(gx, gy, magnitude);
  // Sobel's 3x3 derivative of a ramp of one grey level per pixel is 8: divided, a gradient in
  // grey levels per pixel.
  s.gradient = cv::mean(magnitude)[0] / 8.0;
  s.look_alikes = lookAlikeShare(gray);
  return s;
}

namespace {

Spread spreadOf(std::vector<double> v) {
  if (v.empty()) return {};
  std::sort(v.begin(), v.end());
  auto at = [&](double q) { return v[static_cast<size_t>(std::lround(q * static_cast<double>(v.size() - 1)))]; };
  return {at(0.1), at(0.5), at(0.9)};
}

}  // namespace

SequenceStatistics summarizeStatistics(const std::vector<ImageStatistics>& frames) {
  SequenceStatistics s;
  s.frames = frames.size();
  std::vector<double> c, cells, w, e, g, l;
  for (const auto& f : frames) {
    c.push_back(f.corners);
    cells.push_back(f.cells_covered);
    w.push_back(f.weak_corners);
    e.push_back(f.entropy_bits);
    g.push_back(f.gradient);
    l.push_back(f.look_alikes);
  }
  s.corners = spreadOf(c);
  s.cells_covered = spreadOf(cells);
  s.weak_corners = spreadOf(w);
  s.entropy_bits = spreadOf(e);
  s.gradient = spreadOf(g);
  s.look_alikes = spreadOf(l);
  return s;
}

}  // namespace hiveslam::eval
