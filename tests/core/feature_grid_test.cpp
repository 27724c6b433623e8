// The grid's band walk against a scan of every point: each point within the band of a segment
// is visited, and none twice, for segments of every slope, inside and leaving the image.
#include <gtest/gtest.h>

#include <random>
#include <set>

#include "core/frame/feature_grid.hpp"

namespace hiveslam::core {
namespace {

double distanceToSegment(const Eigen::Vector2d& p, const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  const Eigen::Vector2d d = b - a;
  const double t = d.squaredNorm() > 0 ? std::clamp((p - a).dot(d) / d.squaredNorm(), 0.0, 1.0) : 0.0;
  return (a + t * d - p).norm();
}

TEST(FeatureGrid, TheSegmentWalkVisitsEveryPointInTheBandOnce) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> x(0, 1226), y(0, 370), wide(-2000, 3000);
  std::vector<Eigen::Vector2d> points;
  for (int i = 0; i < 3000; ++i) points.emplace_back(x(rng), y(rng));
  // A few points beyond the grid's bounds, as strong distortion leaves them: edge cells hold them.
  points.emplace_back(-40, 100);
  points.emplace_back(1300, -30);
  const FeatureGrid grid(points, 0, 0, 1226, 370);
  int in_band_total = 0;
  size_t visited_total = 0;
  for (int trial = 0; trial < 400; ++trial) {
    const Eigen::Vector2d a(wide(rng), trial % 2 ? y(rng) : wide(rng)), b(x(rng), y(rng));
    const double half_width = 1 + trial % 7;
    std::multiset<int> visited;
    grid.forEachNearSegment(a, b, half_width, [&](int i) { visited.insert(i); });
    for (int i : visited) ASSERT_EQ(visited.count(i), 1u) << "point " << i << " visited twice";
    for (size_t i = 0; i < points.size(); ++i)
      if (distanceToSegment(points[i], a, b) <= half_width) {
        ++in_band_total;
        ASSERT_TRUE(visited.count(static_cast<int>(i))) << "trial " << trial << ": point " << i << " at ("
                                                        << points[i].transpose() << ") missed";
      }
    visited_total += visited.size();
  }
  EXPECT_GT(in_band_total, 1000);
  // The walk is worth having only if it visits a small part of the image per query.
  EXPECT_LT(visited_total, points.size() * 400 / 5);
}

TEST(FeatureGrid, ADegenerateSegmentIsAPoint) {
  std::vector<Eigen::Vector2d> points{{10, 10}, {12, 10}, {100, 100}};
  const FeatureGrid grid(points, 0, 0, 640, 480);
  std::set<int> visited;
  grid.forEachNearSegment({10, 10}, {10, 10}, 3, [&](int i) { visited.insert(i); });
  EXPECT_TRUE(visited.count(0));
  EXPECT_TRUE(visited.count(1));
  EXPECT_FALSE(visited.count(2));
}

}  // namespace
}  // namespace hiveslam::core
