// Sub-pixel corners against shapes drawn at known, fractional positions.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <opencv2/imgproc.hpp>

#include "core/features/corner_refinement.hpp"

namespace hiveslam::features {
namespace {

// An 8-bit image of `inside` by area sampling (16 x 16 samples a pixel, pixel centres at
// integers), as a camera integrates light, then a little optical blur.
cv::Mat draw(const std::function<bool(double, double)>& inside) {
  cv::Mat f(64, 64, CV_32F);
  constexpr int kSub = 16;
  for (int y = 0; y < f.rows; ++y)
    for (int x = 0; x < f.cols; ++x) {
      int n = 0;
      for (int j = 0; j < kSub; ++j)
        for (int i = 0; i < kSub; ++i) n += inside(x - 0.5 + (i + 0.5) / kSub, y - 0.5 + (j + 0.5) / kSub);
      f.at<float>(y, x) = 40.0f + 160.0f * static_cast<float>(n) / (kSub * kSub);
    }
  cv::GaussianBlur(f, f, cv::Size(5, 5), 0.7);
  cv::Mat img;
  f.convertTo(img, CV_8U);
  return img;
}

// The junction of a checkerboard, turned by `angle`: symmetric, so the response peaks exactly
// on it.
cv::Mat checkerJunction(cv::Point2d at, double angle) {
  const double c = std::cos(angle), s = std::sin(angle);
  return draw([=](double x, double y) {
    const double u = c * (x - at.x) + s * (y - at.y), v = -s * (x - at.x) + c * (y - at.y);
    return (u > 0) == (v > 0);
  });
}

// One bright wedge of 70 degrees: not symmetric, so the peak sits a fixed distance inside the
// tip. What matters for geometry is that it moves with the corner.
cv::Mat wedge(cv::Point2d tip) {
  const double a0 = 0.35, a1 = a0 + 70.0 * M_PI / 180.0;
  return draw([=](double x, double y) {
    const double a = std::atan2(y - tip.y, x - tip.x);
    return a > a0 && a < a1;
  });
}

// Over a grid of fractional positions: within 0.05 px on average and 0.15 px at worst (the
// quadratic fit's pull toward whole and half pixels), where the FAST pixel is off by up to 0.7.
TEST(CornerRefinement, PlacesACheckerboardJunctionBetweenPixels) {
  double sum = 0;
  int n = 0;
  for (double fx = 0.0; fx < 1.0; fx += 0.2)
    for (double fy = 0.1; fy < 1.0; fy += 0.3) {
      const cv::Point2d at(30 + fx, 30 + fy);
      const cv::Mat img = checkerJunction(at, 0.3);
      // Started a pixel or two off, as a FAST pixel may be.
      for (const cv::Point start : {cv::Point(cvRound(at.x), cvRound(at.y)), cv::Point(cvRound(at.x) + 1, cvRound(at.y) - 1),
                                    cv::Point(cvRound(at.x) - 2, cvRound(at.y))}) {
        const auto got = refineCorner(img, start);
        ASSERT_TRUE(got) << at << " from " << start;
        const double error = std::hypot(got->x - at.x, got->y - at.y);
        EXPECT_LT(error, 0.15) << at << " from " << start;
        sum += error;
        ++n;
      }
    }
  EXPECT_LT(sum / n, 0.05);
}

TEST(CornerRefinement, FollowsAFractionalShiftOfAnAsymmetricCorner) {
  const cv::Point2d tip(29.2, 30.6);
  const auto base = refineCorner(wedge(tip), cv::Point(29, 32));
  ASSERT_TRUE(base);
  for (const cv::Point2d shift : {cv::Point2d(0.3, -0.45), cv::Point2d(-0.5, 0.25), cv::Point2d(0.15, 0.1)}) {
    const auto moved = refineCorner(wedge(tip + shift), cv::Point(29, 32));
    ASSERT_TRUE(moved) << shift;
    EXPECT_NEAR(moved->x - base->x, shift.x, 0.1) << shift;
    EXPECT_NEAR(moved->y - base->y, shift.y, 0.1) << shift;
  }
}

TEST(CornerRefinement, NothingWhereThereIsNoCorner) {
  // A straight edge: the response has a ridge along it, no peak.
  const cv::Mat edge = draw([](double x, double y) { return x + 0.4 * y > 40.0; });
  EXPECT_FALSE(refineCorner(edge, cv::Point(28, 30)));
  const cv::Mat flat(64, 64, CV_8U, cv::Scalar(90));
  EXPECT_FALSE(refineCorner(flat, cv::Point(32, 32)));
  // Too close to the border for the window: no read outside the image.
  const cv::Mat img = checkerJunction({4.3, 5.2}, 0.3);
  EXPECT_FALSE(refineCorner(img, cv::Point(4, 5)));
  EXPECT_FALSE(refineCorner(img, cv::Point(63 - kCornerReach + 1, 32)));
}

}  // namespace
}  // namespace hiveslam::features
