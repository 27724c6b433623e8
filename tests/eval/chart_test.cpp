// The plots: round ticks, lines and bars where the data says, and the run's error plots as
// readable PNGs.
#include <gtest/gtest.h>

#include <opencv2/imgcodecs.hpp>

#include "eval/chart.hpp"
#include "eval/error_plots.hpp"
#include "temp_dir.hpp"

namespace hiveslam::eval {
namespace {

int pixelsOf(const cv::Mat& img, const cv::Scalar& color) {
  int n = 0;
  for (int y = 0; y < img.rows; ++y)
    for (int x = 0; x < img.cols; ++x) {
      const cv::Vec3b c = img.at<cv::Vec3b>(y, x);
      if (std::abs(c[0] - color[0]) + std::abs(c[1] - color[1]) + std::abs(c[2] - color[2]) < 30) ++n;
    }
  return n;
}

TEST(Chart, TicksAreRoundAndCoverTheRange) {
  EXPECT_EQ(niceTicks(0, 10, 5), (std::vector<double>{0, 2, 4, 6, 8, 10}));
  const auto t = niceTicks(0.013, 0.087, 6);
  ASSERT_FALSE(t.empty());
  EXPECT_NEAR(t[1] - t[0], 0.02, 1e-12);  // 6 steps of 0.0123: the next round step up
  EXPECT_GE(t.front(), 0.013 - 1e-12);
  EXPECT_LE(t.back(), 0.087 + 1e-12);
  EXPECT_FALSE(niceTicks(5, 5).empty());  // a flat range still gets an axis
}

TEST(Chart, ALineRisesWhereItsDataDoes) {
  const cv::Scalar red(0, 0, 230);
  const cv::Mat img = lineChart({{"rising", red, {0, 1, 2, 3}, {0, 1, 2, 3}}}, {"t", "x", "y", 400, 300});
  ASSERT_EQ(img.cols, 400);
  ASSERT_EQ(img.rows, 300);
  // The line runs from the plot's bottom-left to its top-right: red in both quarters.
  const cv::Mat bottom_left = img(cv::Rect(80, 150, 150, 95)), top_right = img(cv::Rect(230, 40, 150, 110));
  EXPECT_GT(pixelsOf(bottom_left, red), 20);
  EXPECT_GT(pixelsOf(top_right, red), 20);
  EXPECT_EQ(pixelsOf(img(cv::Rect(80, 40, 100, 80)), red), 0);  // nothing top-left
}

TEST(Chart, BarsAreAsTallAsTheirValues) {
  const cv::Scalar blue(200, 60, 20);
  const cv::Mat img = barChart({{"a", 1, -1, blue}, {"b", 4, 5, blue}}, {"", "", "", 400, 300});
  const int a = pixelsOf(img(cv::Rect(80, 0, 150, 300)), blue), b = pixelsOf(img(cv::Rect(230, 0, 150, 300)), blue);
  EXPECT_NEAR(static_cast<double>(b) / a, 4.0, 0.3);
}

TEST(ErrorPlots, WriteTheErrorOverTimeAndPerAxis) {
  AteResult r;
  for (int i = 0; i < 50; ++i) {
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.translation() = Eigen::Vector3d(i * 0.1, 0, 0);
    r.pair.ref.add(i * 0.05, T);
    T.translation().y() = 0.001 * i;
    r.pair.est.add(i * 0.05, T);
    r.errors.push_back(0.001 * i);
  }
  testing::TempDir dir;
  plotErrorOverTime(dir / "t.png", r, "test");
  plotAxisErrors(dir / "xyz.png", r, "test");
  const cv::Mat t = cv::imread((dir / "t.png").string()), xyz = cv::imread((dir / "xyz.png").string());
  ASSERT_FALSE(t.empty());
  ASSERT_FALSE(xyz.empty());
  EXPECT_EQ(xyz.rows, 3 * 260);  // one chart per axis
  EXPECT_GT(pixelsOf(xyz(cv::Rect(0, 260, xyz.cols, 260)), {40, 160, 40}), 50);  // y drifts
}

}  // namespace
}  // namespace hiveslam::eval
