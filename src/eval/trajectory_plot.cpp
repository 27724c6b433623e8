#include "eval/trajectory_plot.hpp"

#include <algorithm>
#include <cmath>
#include <fmt/format.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "common/error.hpp"

namespace hiveslam::eval {

namespace {

const cv::Scalar kRefColor(120, 120, 120), kEstColor(200, 90, 20), kEventColor(30, 30, 220);

}  // namespace

void plotTopView(const std::filesystem::path& png, const io::Trajectory& reference,
                 const io::Trajectory& estimate, const PlotOptions& options) {
  // Axes: the two of largest extent over both trajectories.
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(1e300), hi = -lo;
  for (const auto* t : {&reference, &estimate})
    for (const auto& T : t->poses) {
      lo = lo.cwiseMin(T.translation());
      hi = hi.cwiseMax(T.translation());
    }
  if (reference.empty() && estimate.empty()) lo = hi = Eigen::Vector3d::Zero();
  const Eigen::Vector3d extent = hi - lo;
  int a = 0, b = 1;
  int smallest = 0;
  for (int i = 1; i < 3; ++i)
    if (extent[i] < extent[smallest]) smallest = i;
  a = smallest == 0 ? 1 : 0;
  b = smallest == 2 ? 1 : 2;
  const int size = options.size, margin = 60;
  const double span = std::max({extent[a], extent[b], 1e-6});
  const double scale = (size - 2 * margin) / span;
  auto px = [&](const Eigen::Vector3d& p) {
    return cv::Point2d(margin + (p[a] - lo[a]) * scale, size - margin - (p[b] - lo[b]) * scale);
  };
  cv::Mat img(size, size, CV_8UC3, cv::Scalar(255, 255, 255));
  constexpr int kShift = 4;  // sub-pixel drawing
  auto draw = [&](const io::Trajectory& t, const cv::Scalar& color, int thickness) {
    std::vector<cv::Point> pts;
    for (const auto& T : t.poses) {
      const cv::Point2d q = px(T.translation());
      pts.emplace_back(cvRound(q.x * (1 << kShift)), cvRound(q.y * (1 << kShift)));
    }
    if (pts.size() > 1) cv::polylines(img, pts, false, color, thickness, cv::LINE_AA, kShift);
  };
  draw(reference, kRefColor, 2);
  draw(estimate, kEstColor, 2);
  for (const auto& e : options.events) {
    if (estimate.empty()) break;
    size_t best = 0;
    for (size_t i = 1; i < estimate.size(); ++i)
      if (std::abs(estimate.stamps[i] - e.stamp) < std::abs(estimate.stamps[best] - e.stamp)) best = i;
    const cv::Point2d q = px(estimate.poses[best].translation());
    cv::circle(img, q, 6, kEventColor, 2, cv::LINE_AA);
    cv::putText(img, e.label, q + cv::Point2d(8, -8), cv::FONT_HERSHEY_SIMPLEX, 0.5, kEventColor, 1,
                cv::LINE_AA);
  }
  // Legend, title and a scale bar of a round length.
  const char* names = "xyz";
  cv::putText(img, options.title, {margin, 30}, cv::FONT_HERSHEY_SIMPLEX, 0.6, {0, 0, 0}, 1, cv::LINE_AA);
  cv::line(img, {size - 230, 25}, {size - 200, 25}, kRefColor, 2, cv::LINE_AA);
  cv::putText(img, "ground truth", {size - 192, 30}, cv::FONT_HERSHEY_SIMPLEX, 0.5, {0, 0, 0}, 1, cv::LINE_AA);
  cv::line(img, {size - 230, 45}, {size - 200, 45}, kEstColor, 2, cv::LINE_AA);
  cv::putText(img, "estimate", {size - 192, 50}, cv::FONT_HERSHEY_SIMPLEX, 0.5, {0, 0, 0}, 1, cv::LINE_AA);
  const double bar = std::pow(10.0, std::floor(std::log10(span / 4)));
  const int bar_px = static_cast<int>(bar * scale);
  cv::line(img, {margin, size - 25}, {margin + bar_px, size - 25}, {0, 0, 0}, 2);
  cv::putText(img, fmt::format("{:g} m   (view: {} right, {} up)", bar, names[a], names[b]),
              {margin, size - 8}, cv::FONT_HERSHEY_SIMPLEX, 0.45, {0, 0, 0}, 1, cv::LINE_AA);
  if (png.has_parent_path()) std::filesystem::create_directories(png.parent_path());
  if (!cv::imwrite(png.string(), img)) throw InputError("cannot write plot " + png.string());
}

}  // namespace hiveslam::eval
