#include <gtest/gtest.h>

#include <cmath>
#include <opencv2/imgcodecs.hpp>

#include "common/error.hpp"
#include "eval/trajectory_error.hpp"
#include "eval/trajectory_plot.hpp"
#include "temp_dir.hpp"

namespace hiveslam::eval {
namespace {

Eigen::Isometry3d at(double x, double y, double z) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translation() = Eigen::Vector3d(x, y, z);
  return T;
}

io::Trajectory square() {
  io::Trajectory t;
  t.add(0.0, at(0, 0, 0));
  t.add(1.0, at(1, 0, 0));
  t.add(2.0, at(1, 1, 0));
  t.add(3.0, at(0, 1, 1));
  return t;
}

TEST(Association, FollowsEvoRules) {
  io::Trajectory ref, est;
  for (int i = 0; i < 10; ++i) ref.add(0.1 * i, at(i, 0, 0));
  est.add(0.004, at(0, 0, 0));    // -> ref 0
  est.add(0.105, at(0, 0, 0));    // -> ref 1 (0.005 away)
  est.add(0.106, at(0, 0, 0));    // -> ref 1 again: not one-to-one
  est.add(0.25, at(0, 0, 0));     // tie between 0.2 and 0.3: the first one
  est.add(0.52, at(0, 0, 0));     // 0.02 from ref 5: dropped at max_diff 0.01
  const Association a = associateByTime(ref, est, 0.01);
  ASSERT_EQ(a.size(), 3u);
  EXPECT_EQ(a.ref, (std::vector<size_t>{0, 1, 1}));
  EXPECT_EQ(a.est, (std::vector<size_t>{0, 1, 2}));
  const Association wide = associateByTime(ref, est, 0.05);
  ASSERT_EQ(wide.size(), 5u);
  EXPECT_EQ(wide.ref[3], 2u);
  EXPECT_EQ(wide.ref[4], 5u);
}

TEST(Association, IteratesOverTheShorterTrajectory) {
  // Ground truth shorter than the estimate: each ground-truth pose picks its nearest estimate.
  io::Trajectory ref, est;
  ref.add(1.0, at(0, 0, 0));
  ref.add(2.0, at(0, 0, 0));
  for (int i = 0; i < 30; ++i) est.add(0.9 + 0.05 * i, at(0, 0, 0));
  const Association a = associateByTime(ref, est, 0.01);
  ASSERT_EQ(a.size(), 2u);
  EXPECT_EQ(a.ref, (std::vector<size_t>{0, 1}));
  EXPECT_EQ(a.est, (std::vector<size_t>{2, 22}));
}

TEST(Ate, HandComputedWithoutAlignment) {
  const io::Trajectory ref = square();
  io::Trajectory est = ref;
  // Position errors of 1, 2, 3, 4 metres along different axes.
  est.poses[0].translation() += Eigen::Vector3d(1, 0, 0);
  est.poses[1].translation() += Eigen::Vector3d(0, 2, 0);
  est.poses[2].translation() += Eigen::Vector3d(0, 0, -3);
  est.poses[3].translation() += Eigen::Vector3d(0, 4, 0);
  MatchOptions o;
  o.alignment = Alignment::None;
  const AteResult r = computeAte(ref, est, o);
  EXPECT_EQ(r.stats.count, 4u);
  EXPECT_DOUBLE_EQ(r.stats.rmse, std::sqrt(30.0 / 4.0));
  EXPECT_DOUBLE_EQ(r.stats.mean, 2.5);
  EXPECT_DOUBLE_EQ(r.stats.median, 2.5);
  EXPECT_DOUBLE_EQ(r.stats.std, std::sqrt(1.25));  // population std
  EXPECT_DOUBLE_EQ(r.stats.min, 1.0);
  EXPECT_DOUBLE_EQ(r.stats.max, 4.0);
  EXPECT_DOUBLE_EQ(r.stats.sse, 30.0);
}

TEST(Ate, HandComputedOddMedianAndConstantOffset) {
  io::Trajectory ref = square();
  ref.add(4.0, at(2, 2, 2));
  io::Trajectory est = ref;
  for (auto& T : est.poses) T.translation() += Eigen::Vector3d(0.3, 0.0, 0.4);
  MatchOptions o;
  o.alignment = Alignment::None;
  const AteResult r = computeAte(ref, est, o);
  EXPECT_NEAR(r.stats.rmse, 0.5, 1e-12);
  EXPECT_NEAR(r.stats.median, 0.5, 1e-12);
  EXPECT_NEAR(r.stats.std, 0.0, 1e-12);
  // The same offset vanishes under SE3 alignment.
  o.alignment = Alignment::SE3;
  EXPECT_NEAR(computeAte(ref, est, o).stats.rmse, 0.0, 1e-12);
}

TEST(Ate, Sim3AlignmentRemovesScaleRotationAndTranslation) {
  io::Trajectory ref;
  for (int i = 0; i < 40; ++i) ref.add(0.05 * i, at(std::cos(0.2 * i), std::sin(0.3 * i), 0.02 * i));
  io::Trajectory est;
  const Eigen::Matrix3d R = Eigen::AngleAxisd(0.9, Eigen::Vector3d(1, 1, 0).normalized()).toRotationMatrix();
  for (size_t i = 0; i < ref.size(); ++i) {
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.translation() = 0.3 * (R * ref.poses[i].translation()) + Eigen::Vector3d(5, 6, 7);
    est.add(ref.stamps[i] + 0.003, T);
  }
  const AteResult sim3 = computeAte(ref, est);
  EXPECT_NEAR(sim3.stats.rmse, 0.0, 1e-10);
  EXPECT_NEAR(sim3.pair.alignment.scale, 1.0 / 0.3, 1e-10);
  MatchOptions se3;
  se3.alignment = Alignment::SE3;
  EXPECT_GT(computeAte(ref, est, se3).stats.rmse, 0.1);  // scale is not corrected
}

TEST(Ate, TooFewMatchesIsAnError) {
  io::Trajectory ref = square(), est = square();
  for (auto& t : est.stamps) t += 100.0;
  EXPECT_THROW(computeAte(ref, est), InputError);
}

TEST(Ate, KittiPairsByLine) {
  const io::Trajectory ref = square();
  io::Trajectory est;
  for (size_t i = 0; i < ref.size(); ++i) est.add(static_cast<double>(i) * 7, ref.poses[i]);
  MatchOptions o;
  o.by_index = true;
  EXPECT_EQ(computeAte(ref, est, o).stats.count, 4u);
  est.add(99, at(0, 0, 0));
  EXPECT_THROW(computeAte(ref, est, o), InputError);
}

TEST(Rpe, ConstantStepErrorPerFrame) {
  io::Trajectory ref, est;
  for (int i = 0; i < 11; ++i) {
    ref.add(i, at(i, 0, 0));
    est.add(i, at(1.1 * i, 0, 0));  // every step 10 cm too long
  }
  RpeOptions o;
  o.match.alignment = Alignment::None;
  RpeResult r = computeRpe(ref, est, o);
  EXPECT_EQ(r.pairs.size(), 10u);
  EXPECT_NEAR(r.stats.rmse, 0.1, 1e-12);
  o.delta = 2;
  r = computeRpe(ref, est, o);
  EXPECT_EQ(r.pairs.size(), 5u);
  EXPECT_NEAR(r.stats.mean, 0.2, 1e-12);
  o.all_pairs = true;
  EXPECT_EQ(computeRpe(ref, est, o).pairs.size(), 9u);
  o.delta = 3;
  o.all_pairs = false;
  o.unit = DeltaUnit::Meters;
  r = computeRpe(ref, est, o);
  EXPECT_EQ(r.pairs.front(), (std::pair<size_t, size_t>{0, 3}));
  EXPECT_NEAR(r.stats.mean, 0.3, 1e-12);
}

TEST(Rpe, RotationErrorInDegrees) {
  io::Trajectory ref, est;
  for (int i = 0; i < 5; ++i) {
    ref.add(i, at(i, 0, 0));
    Eigen::Isometry3d T = at(i, 0, 0);
    T.linear() = Eigen::AngleAxisd(i * M_PI / 180.0, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    est.add(i, T);
  }
  RpeOptions o;
  o.match.alignment = Alignment::None;
  o.relation = RpeRelation::RotationDeg;
  EXPECT_NEAR(computeRpe(ref, est, o).stats.mean, 1.0, 1e-9);
}

TEST(Plot, WritesATopViewPng) {
  testing::TempDir dir;
  io::Trajectory ref = square(), est = square();
  plotTopView(dir / "plot.png", ref, est, {"test", 400, {{1.0, "loop"}}});
  const cv::Mat img = cv::imread((dir / "plot.png").string());
  ASSERT_FALSE(img.empty());
  EXPECT_EQ(img.size(), cv::Size(400, 400));
}

}  // namespace
}  // namespace hiveslam::eval
