#include "eval/chart.hpp"

#include <fmt/format.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>

#include "common/error.hpp"

namespace hiveslam::eval {

namespace {

const cv::Scalar kInk(40, 40, 40), kGrid(225, 225, 225);
constexpr int kLeft = 80, kRight = 20, kTop = 40, kBottom = 55;
constexpr auto kFont = cv::FONT_HERSHEY_SIMPLEX;

void text(cv::Mat& img, const std::string& s, cv::Point at, double size = 0.45, const cv::Scalar& color = kInk) {
  cv::putText(img, s, at, kFont, size, color, 1, cv::LINE_AA);
}

int textWidth(const std::string& s, double size = 0.45) {
  int base = 0;
  return cv::getTextSize(s, kFont, size, 1, &base).width;
}

std::string tickLabel(double v) { return std::abs(v) < 1e-12 ? "0" : fmt::format("{:.4g}", v); }

// The frame, title, axis labels and y ticks; returns the plot area.
cv::Rect frame(cv::Mat& img, const ChartOptions& o, const std::vector<double>& y_ticks, double y_lo, double y_hi) {
  const cv::Rect area(kLeft, kTop, o.width - kLeft - kRight, o.height - kTop - kBottom);
  text(img, o.title, {kLeft, 24}, 0.55);
  for (double t : y_ticks) {
    const int y = area.y + area.height - static_cast<int>((t - y_lo) / (y_hi - y_lo) * area.height);
    cv::line(img, {area.x, y}, {area.x + area.width, y}, kGrid, 1);
    const std::string s = tickLabel(t);
    text(img, s, {area.x - 8 - textWidth(s), y + 5});
  }
  cv::rectangle(img, area, kInk, 1);
  text(img, o.x_label, {area.x + area.width / 2 - textWidth(o.x_label) / 2, o.height - 10});
  // The y label, written sideways.
  if (!o.y_label.empty()) {
    cv::Mat label(24, textWidth(o.y_label) + 4, CV_8UC3, cv::Scalar(255, 255, 255));
    text(label, o.y_label, {2, 17});
    cv::Mat turned;
    cv::rotate(label, turned, cv::ROTATE_90_COUNTERCLOCKWISE);
    const int y0 = std::max(0, area.y + area.height / 2 - turned.rows / 2);
    if (y0 + turned.rows <= img.rows && turned.cols <= img.cols) turned.copyTo(img(cv::Rect(4, y0, turned.cols, turned.rows)));
  }
  return area;
}

}  // namespace

std::vector<double> niceTicks(double lo, double hi, int count) {
  if (!(hi > lo)) hi = lo + 1;
  const double raw = (hi - lo) / std::max(count, 1);
  const double power = std::pow(10.0, std::floor(std::log10(raw)));
  double step = power;
  for (double m : {1.0, 2.0, 5.0, 10.0})
    if (m * power >= raw) {
      step = m * power;
      break;
    }
  std::vector<double> ticks;
  const double first = std::ceil(lo / step - 1e-9);
  for (int i = 0; (first + i) * step <= hi + step * 1e-9; ++i) ticks.push_back((first + i) * step);
  return ticks;
}

cv::Mat lineChart(const std::vector<Series>& series, const ChartOptions& o) {
  cv::Mat img(o.height, o.width, CV_8UC3, cv::Scalar(255, 255, 255));
  double x_lo = 1e300, x_hi = -1e300, y_lo = 1e300, y_hi = -1e300;
  for (const auto& s : series)
    for (size_t i = 0; i < std::min(s.x.size(), s.y.size()); ++i) {
      if (!std::isfinite(s.x[i]) || !std::isfinite(s.y[i])) continue;
      x_lo = std::min(x_lo, s.x[i]);
      x_hi = std::max(x_hi, s.x[i]);
      y_lo = std::min(y_lo, s.y[i]);
      y_hi = std::max(y_hi, s.y[i]);
    }
  if (x_lo > x_hi) x_lo = 0, x_hi = 1, y_lo = 0, y_hi = 1;
  if (x_hi - x_lo < 1e-12) x_hi = x_lo + 1;
  if (y_hi - y_lo < 1e-12) y_hi = y_lo + 1;
  const auto y_ticks = niceTicks(y_lo, y_hi);
  y_lo = std::min(y_lo, y_ticks.front());
  y_hi = std::max(y_hi, y_ticks.back());
  const cv::Rect area = frame(img, o, y_ticks, y_lo, y_hi);
  auto px = [&](double x, double y) {
    return cv::Point2d(area.x + (x - x_lo) / (x_hi - x_lo) * area.width, area.y + area.height - (y - y_lo) / (y_hi - y_lo) * area.height);
  };
  for (double t : niceTicks(x_lo, x_hi, 8)) {
    const cv::Point2d p = px(t, y_lo);
    cv::line(img, p, p + cv::Point2d(0, 5), kInk, 1);
    const std::string s = tickLabel(t);
    text(img, s, {static_cast<int>(p.x) - textWidth(s) / 2, area.y + area.height + 20});
  }
  constexpr int kShift = 4;
  int legend_x = area.x + area.width;
  for (auto it = series.rbegin(); it != series.rend(); ++it) {
    std::vector<cv::Point> pts;
    for (size_t i = 0; i < std::min(it->x.size(), it->y.size()); ++i) {
      if (!std::isfinite(it->x[i]) || !std::isfinite(it->y[i])) continue;
      const cv::Point2d p = px(it->x[i], it->y[i]);
      pts.emplace_back(cvRound(p.x * (1 << kShift)), cvRound(p.y * (1 << kShift)));
    }
    if (pts.size() > 1) cv::polylines(img, pts, false, it->color, 1, cv::LINE_AA, kShift);
    legend_x -= textWidth(it->name) + 40;
    cv::line(img, {legend_x, 20}, {legend_x + 25, 20}, it->color, 2, cv::LINE_AA);
    text(img, it->name, {legend_x + 30, 25});
  }
  return img;
}

cv::Mat barChart(const std::vector<Bar>& bars, const ChartOptions& o) {
  cv::Mat img(o.height, o.width, CV_8UC3, cv::Scalar(255, 255, 255));
  double hi = 0;
  for (const auto& b : bars) hi = std::max({hi, b.value, b.whisker});
  if (hi <= 0) hi = 1;
  const auto ticks = niceTicks(0, hi);
  hi = std::max(hi, ticks.back());
  const cv::Rect area = frame(img, o, ticks, 0, hi);
  const double slot = static_cast<double>(area.width) / std::max<size_t>(bars.size(), 1);
  auto y_of = [&](double v) { return area.y + area.height - static_cast<int>(v / hi * area.height); };
  for (size_t i = 0; i < bars.size(); ++i) {
    const auto& b = bars[i];
    const int x0 = area.x + static_cast<int>(i * slot + slot * 0.2), x1 = area.x + static_cast<int>((i + 1) * slot - slot * 0.2);
    cv::rectangle(img, cv::Point(x0, y_of(b.value)), cv::Point(x1, area.y + area.height), b.color, cv::FILLED);
    if (b.whisker >= b.value) {
      const int xm = (x0 + x1) / 2, yw = y_of(b.whisker);
      cv::line(img, {xm, y_of(b.value)}, {xm, yw}, kInk, 1);
      cv::line(img, {xm - 6, yw}, {xm + 6, yw}, kInk, 1);
    }
    // Labels under the bar, shrunk to its slot.
    const double size = std::min(0.45, 0.45 * slot / std::max(textWidth(b.label), 1));
    text(img, b.label, {area.x + static_cast<int>(i * slot + slot / 2) - textWidth(b.label, size) / 2, area.y + area.height + 20},
         size);
  }
  return img;
}

void writeCharts(const std::filesystem::path& png, const std::vector<cv::Mat>& charts) {
  if (charts.empty()) return;
  int width = 0;
  for (const auto& c : charts) width = std::max(width, c.cols);
  std::vector<cv::Mat> padded;
  for (const auto& c : charts) {
    cv::Mat p;
    cv::copyMakeBorder(c, p, 0, 0, 0, width - c.cols, cv::BORDER_CONSTANT, cv::Scalar(255, 255, 255));
    padded.push_back(p);
  }
  cv::Mat all;
  cv::vconcat(padded, all);
  if (png.has_parent_path()) std::filesystem::create_directories(png.parent_path());
  if (!cv::imwrite(png.string(), all)) throw InputError("cannot write plot " + png.string());
}

}  // namespace hiveslam::eval
