#include "eval/error_plots.hpp"

#include <fmt/format.h>

#include "eval/chart.hpp"

namespace hiveslam::eval {

namespace {

std::vector<double> secondsSinceFirst(const io::Trajectory& t) {
  std::vector<double> s;
  s.reserve(t.size());
  for (double stamp : t.stamps) s.push_back(stamp - (t.empty() ? 0 : t.stamps.front()));
  return s;
}

}  // namespace

void plotErrorOverTime(const std::filesystem::path& png, const AteResult& ate, const std::string& title) {
  std::vector<double> mm;
  for (double e : ate.errors) mm.push_back(1000 * e);
  writeCharts(png, {lineChart({{"position error", {200, 90, 20}, secondsSinceFirst(ate.pair.est), mm}},
                              {title, "time (s)", "error (mm)"})});
}

void plotAxisErrors(const std::filesystem::path& png, const AteResult& ate, const std::string& title) {
  const auto t = secondsSinceFirst(ate.pair.est);
  const char* names[] = {"x", "y", "z"};
  const cv::Scalar colors[] = {{40, 40, 220}, {40, 160, 40}, {200, 90, 20}};
  std::vector<cv::Mat> charts;
  for (int axis = 0; axis < 3; ++axis) {
    std::vector<double> d;
    for (size_t i = 0; i < ate.pair.est.size() && i < ate.pair.ref.size(); ++i)
      d.push_back(1000 * (ate.pair.est.poses[i].translation()[axis] - ate.pair.ref.poses[i].translation()[axis]));
    charts.push_back(lineChart({{fmt::format("{} error", names[axis]), colors[axis], t, d}},
                               {axis == 0 ? title : "", "time (s)", fmt::format("{} (mm)", names[axis]), 900, 260}));
  }
  writeCharts(png, charts);
}

}  // namespace hiveslam::eval
