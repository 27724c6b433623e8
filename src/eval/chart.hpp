#pragma once
// Line and bar charts as images (OpenCV drawing): axes with round ticks, a legend, a title.
// What hiveslam's plots are drawn with (error over time, per axis, a bench's table).
#include <opencv2/core.hpp>

#include <filesystem>
#include <string>
#include <vector>

namespace hiveslam::eval {

struct ChartOptions {
  std::string title, x_label, y_label;
  int width = 900, height = 380;
};

struct Series {
  std::string name;
  cv::Scalar color;
  std::vector<double> x, y;
};

struct Bar {
  std::string label;
  double value = 0;      // drawn as the bar (a median)
  double whisker = -1;   // drawn as a tick above it when >= value (the worst run)
  cv::Scalar color;
};

cv::Mat lineChart(const std::vector<Series>& series, const ChartOptions& options);
cv::Mat barChart(const std::vector<Bar>& bars, const ChartOptions& options);
// Charts one above the other (widths padded to the widest), written as PNG.
void writeCharts(const std::filesystem::path& png, const std::vector<cv::Mat>& charts);

// Round tick values covering [lo, hi]: steps of 1, 2 or 5 times a power of ten, about `count`.
std::vector<double> niceTicks(double lo, double hi, int count = 6);

}  // namespace hiveslam::eval
