#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "common/error.hpp"
#include "eval/scale_precision.hpp"
#include "eval/scale_step.hpp"
#include "eval/stretch_errors.hpp"

namespace hiveslam::eval {
namespace {

Eigen::Isometry3d at(const Eigen::Vector3d& p) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translation() = p;
  return T;
}

// An L-shaped path sampled at 10 Hz: 10 s east, then 10 s north.
io::Trajectory lPath() {
  io::Trajectory t;
  for (int i = 0; i <= 200; ++i) {
    const double s = 0.1 * i;
    t.add(100.0 + s, at(s <= 10 ? Eigen::Vector3d(0.3 * s, 0, 1) : Eigen::Vector3d(3, 0.3 * (s - 10), 1)));
  }
  return t;
}

// A run whose first quarter came out at twice the size of the rest (a young map rescaled): the
// stretches' own scales say so, and the error sits in them.
TEST(StretchErrors, ShowWhereAYoungMapsScaleJumps) {
  const io::Trajectory truth = lPath();
  const Eigen::Matrix3d R = Eigen::AngleAxisd(0.4, Eigen::Vector3d(0, 1, 1).normalized()).toRotationMatrix();
  io::Trajectory est;
  const Eigen::Vector3d knee = truth.poses[50].translation();  // 5 s in
  for (size_t i = 0; i < truth.size(); ++i) {
    Eigen::Vector3d p = truth.poses[i].translation();
    p = i < 50 ? knee + 2.0 * (p - knee) : p;  // the first 5 s twice as large
    est.add(truth.stamps[i], at(3.0 * (R * p)));  // the whole map at 3x
  }
  const auto ate = computeAte(truth, est);
  const auto stretches = stretchErrors(ate, 4);
  ASSERT_EQ(stretches.size(), 4u);
  EXPECT_EQ(stretches[0].poses + stretches[1].poses + stretches[2].poses + stretches[3].poses, truth.size());
  EXPECT_NEAR(stretches[0].scale, 1.0 / 6.0, 1e-3);  // reference metres per estimate unit
  for (size_t k = 1; k < 4; ++k) EXPECT_NEAR(stretches[k].scale, 1.0 / 3.0, 1e-3) << k;
  EXPECT_GT(stretches[0].mean_error, 2 * stretches[2].mean_error);
  EXPECT_THROW(stretchErrors(ate, 0), InputError);
}

// A camera that pans 40 degrees in each of four stretches, estimated by a run whose lens made
// every pan 10% too wide but the third (a standstill in the truth, a 5-degree drift in the
// estimate): each stretch's turns and their difference say so, whatever frame the estimate is in.
TEST(StretchErrors, ShowHowFarEachStretchTurned) {
  io::Trajectory truth, est;
  const Eigen::Matrix3d frame = Eigen::AngleAxisd(1.1, Eigen::Vector3d(1, 2, 0).normalized()).toRotationMatrix();
  double true_yaw = 0, est_yaw = 0;
  for (int i = 0; i <= 400; ++i) {
    const int stretch = std::min(i / 100, 3);
    const bool still = stretch == 2;
    if (i > 0) {
      true_yaw += still ? 0.0 : 0.4;
      est_yaw += still ? 0.05 : 0.44;
    }
    const Eigen::Vector3d p(0.01 * i, 0.02 * std::sin(0.05 * i), 1);
    Eigen::Isometry3d t = at(p), e = at(2.0 * (frame * p));
    t.linear() = Eigen::AngleAxisd(true_yaw * M_PI / 180, Eigen::Vector3d::UnitY()).toRotationMatrix();
    e.linear() = frame * Eigen::AngleAxisd(est_yaw * M_PI / 180, Eigen::Vector3d::UnitY()).toRotationMatrix();
    truth.add(100.0 + 0.1 * i, t);
    est.add(100.0 + 0.1 * i, e);
  }
  const auto stretches = stretchErrors(computeAte(truth, est), 4);
  ASSERT_EQ(stretches.size(), 4u);
  for (size_t k : {0u, 1u, 3u}) {
    const double steps = static_cast<double>(stretches[k].poses - 1);
    EXPECT_NEAR(stretches[k].turn, 0.4 * steps, 1e-6) << k;
    EXPECT_NEAR(stretches[k].turn_estimate, 0.44 * steps, 1e-6) << k;
    EXPECT_NEAR(stretches[k].turn_error, 0.04 * steps, 1e-6) << k;
  }
  EXPECT_NEAR(stretches[2].turn, 0.0, 1e-6);
  EXPECT_NEAR(stretches[2].turn_estimate, 0.05 * static_cast<double>(stretches[2].poses - 1), 1e-6);
}

TEST(ScaleStep, MeasuresTheStepOfAPathScaledAfterItsTurn) {
  const io::Trajectory truth = lPath();
  // The estimate: the truth in another frame at half size, its second leg 2% longer than it
  // should be (scaled about the corner).
  const Eigen::Matrix3d R = Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  const Eigen::Vector3d corner(3, 0, 1);
  io::Trajectory est;
  for (size_t i = 0; i < truth.size(); ++i) {
    Eigen::Vector3d p = truth.poses[i].translation();
    if (truth.stamps[i] - 100.0 > 10) p = corner + 1.02 * (p - corner);
    est.add(truth.stamps[i], at(0.5 * (R * p) + Eigen::Vector3d(4, -1, 2)));
  }
  const ScaleStep s = computeScaleStep(truth, est, {8.0, 12.0});
  EXPECT_NEAR(s.step(), 1.02, 1e-9);
  EXPECT_NEAR(s.first_scale, 0.5, 1e-9);
  EXPECT_NEAR(s.second_scale, 0.51, 1e-9);
  EXPECT_EQ(s.first_poses, 81u);
  EXPECT_EQ(s.second_poses, 81u);
  EXPECT_NEAR(computeScaleStep(truth, truth, {8.0, 12.0}).step(), 1.0, 1e-12);
}

// A merged map's two sides need not be the run's two ends: the bounds pick the middle stretches.
// Here the path's last 4 s are scaled by another 5% (about the 16 s point), which bounded
// stretches leave out and unbounded ones would take in.
TEST(ScaleStep, BoundedStretchesLeaveTheRestOfThePathOut) {
  const io::Trajectory truth = lPath();
  const Eigen::Vector3d corner(3, 0, 1), late(3, 1.8, 1);
  io::Trajectory est;
  for (size_t i = 0; i < truth.size(); ++i) {
    Eigen::Vector3d p = truth.poses[i].translation();
    const double t = truth.stamps[i] - 100.0;
    if (t > 16) p = late + 1.05 * (p - late);
    if (t > 10) p = corner + 1.02 * (p - corner);
    est.add(truth.stamps[i], at(p));
  }
  StretchSplit split{8.0, 12.0};
  split.first_from = 2.0;
  split.second_until = 16.0;
  const ScaleStep s = computeScaleStep(truth, est, split);
  EXPECT_NEAR(s.step(), 1.02, 1e-9);
  EXPECT_EQ(s.first_poses, 61u);
  EXPECT_EQ(s.second_poses, 41u);
  EXPECT_GT(std::abs(computeScaleStep(truth, est, {8.0, 12.0}).step() - 1.02), 0.005);
}

TEST(ScaleStep, AStretchWithoutPosesIsAnInputError) {
  const io::Trajectory truth = lPath();
  EXPECT_THROW(computeScaleStep(truth, truth, {8.0, 30.0}), InputError);
  EXPECT_THROW(computeScaleStep(truth, io::Trajectory{}, {8.0, 12.0}), InputError);
}

// Sixteen cameras walking along x past a textured wall 3-5 m away, one per second; the
// first is fixed (the gauge), the scale is left to the points as in a monocular map.
struct WallWalk {
  core::BaProblem problem;
  std::vector<double> stamps;
};

WallWalk wallWalk(double noise_px) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(0, 1);
  std::normal_distribution<double> n(0, 1);
  WallWalk w;
  w.problem.K = {450, 450, 376, 240};
  for (int c = 0; c < 16; ++c) {
    w.problem.poses.push_back({Eigen::Quaterniond::Identity(), Eigen::Vector3d(-0.25 * c, 0, 0), c == 0});
    w.stamps.push_back(50.0 + c);
  }
  for (int i = 0; i < 600; ++i) {
    const Eigen::Vector3d p(-2 + 8 * u(rng), -1.5 + 3 * u(rng), 3 + 2 * u(rng));
    std::vector<core::BaObservation> seen;
    for (int c = 0; c < 16; ++c) {
      const auto& pose = w.problem.poses[static_cast<size_t>(c)];
      const Eigen::Vector2d uv = w.problem.K.project(pose.q_cw * p + pose.t_cw);
      if (uv.x() < 0 || uv.x() > 752 || uv.y() < 0 || uv.y() > 480) continue;
      const double inv_sigma = (i % 3 == 0) ? 1.0 / 1.44 : 1.0;  // a third on pyramid level 2
      seen.push_back({c, 0, uv + noise_px / inv_sigma * Eigen::Vector2d(n(rng), n(rng)), inv_sigma});
    }
    if (seen.size() < 2) continue;
    for (auto& ob : seen) ob.point = static_cast<int>(w.problem.points.size());
    w.problem.points.push_back({p, false});
    w.problem.observations.insert(w.problem.observations.end(), seen.begin(), seen.end());
  }
  return w;
}

TEST(ScalePrecision, ResidualNoiseOfAFittedMapGivesBackTheNoiseThatWasAdded) {
  WallWalk w = wallWalk(0.5);
  core::BaOptions o;
  o.iterations = 30;
  o.outliers = core::Outliers::Kept;
  core::bundleAdjust(w.problem, o);
  EXPECT_NEAR(residualNoise(w.problem), 0.5, 0.03);
  EXPECT_NEAR(residualNoise(wallWalk(0.0).problem), 0.0, 1e-9);
}

TEST(ScalePrecision, StepSpreadIsZeroWithoutNoiseAndGrowsInProportionToIt) {
  const WallWalk w = wallWalk(0.0);
  ScalePrecisionOptions o;
  o.split = {4.0, 11.0};  // times count from the first keyframe (stamp 50)
  o.trials = 12;
  o.noise = 1e-9;
  const ScalePrecision none = computeScalePrecision(w.problem, w.stamps, o);
  EXPECT_EQ(none.first_keyframes, 5u);
  EXPECT_EQ(none.second_keyframes, 5u);
  ASSERT_EQ(none.steps.size(), 12u);
  EXPECT_LT(none.sd, 1e-6);
  EXPECT_NEAR(none.mean, 1.0, 1e-6);

  o.noise = 0.5;
  const ScalePrecision half = computeScalePrecision(w.problem, w.stamps, o);
  o.noise = 1.0;
  const ScalePrecision one = computeScalePrecision(w.problem, w.stamps, o);
  EXPECT_GT(half.sd, 1e-4);  // the noise reaches the scale...
  EXPECT_LT(one.sd, 0.05);   // ...but a wall seen by 16 cameras holds it to a few percent
  // Same draws, twice as large: the step's spread doubles (the problem is nearly linear).
  EXPECT_NEAR(one.sd / half.sd, 2.0, 0.2);
  EXPECT_NEAR(half.noise, 0.5, 1e-12);
}

TEST(ScalePrecision, NeedsKeyframesInBothStretches) {
  const WallWalk w = wallWalk(0.0);
  ScalePrecisionOptions o;
  o.split = {4.0, 40.0};
  EXPECT_THROW(computeScalePrecision(w.problem, w.stamps, o), InputError);
  EXPECT_THROW(computeScalePrecision(w.problem, {1.0, 2.0}, o), InputError);
}

}  // namespace
}  // namespace hiveslam::eval
