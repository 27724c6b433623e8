// A whole-map BA fixes one pose: the map's scale about it is free, and a solve can leave the
// map at another scale with every residual unchanged. restoreScale puts it back.
#include <gtest/gtest.h>

#include <random>

#include "core/optim/scale_gauge.hpp"

namespace hiveslam::core {
namespace {

BaProblem cameraRowOverPoints(std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-1, 1);
  BaProblem pb;
  pb.K = {450, 450, 376, 240};
  for (int c = 0; c < 6; ++c) {
    const Eigen::Matrix3d R = Eigen::AngleAxisd(-0.1 * c, Eigen::Vector3d::UnitY()).toRotationMatrix();
    const Eigen::Vector3d centre(0.3 * c + 0.5, 0.02 * c - 0.3, 0.1);
    pb.poses.push_back({Eigen::Quaterniond(R.transpose()), -(R.transpose() * centre), c == 0});
  }
  for (int i = 0; i < 50; ++i) pb.points.push_back({Eigen::Vector3d(1.5 * u(rng), u(rng), 4 + u(rng)), false});
  return pb;
}

// Every free pose and point scaled by s about the fixed camera's centre: the same residuals.
void scaleAboutTheFixedCamera(BaProblem& pb, double s) {
  const Eigen::Vector3d o = cameraCentres(pb)[0];
  const auto centres = cameraCentres(pb);
  for (size_t i = 1; i < pb.poses.size(); ++i) pb.poses[i].t_cw = -(pb.poses[i].q_cw * (o + s * (centres[i] - o)));
  for (auto& p : pb.points) p.p_w = o + s * (p.p_w - o);
}

TEST(ScaleGauge, AMapThatShrankInTheFreeDirectionIsPutBackAtItsScale) {
  std::mt19937 rng(3);
  const BaProblem truth = cameraRowOverPoints(rng);
  BaProblem solved = truth;
  scaleAboutTheFixedCamera(solved, 1.0 / 80);
  const double s = restoreScale(solved, cameraCentres(truth));
  EXPECT_NEAR(s, 80.0, 1e-9);
  for (size_t i = 0; i < truth.poses.size(); ++i) {
    EXPECT_LT((solved.poses[i].t_cw - truth.poses[i].t_cw).norm(), 1e-9) << "pose " << i;
    EXPECT_LT(solved.poses[i].q_cw.angularDistance(truth.poses[i].q_cw), 1e-12) << "pose " << i;
  }
  for (size_t i = 0; i < truth.points.size(); ++i)
    EXPECT_LT((solved.points[i].p_w - truth.points[i].p_w).norm(), 1e-9) << "point " << i;
}

// A real correction (one camera moved) is kept: only the common scale is taken back.
TEST(ScaleGauge, WhatTheSolveChangedBesidesTheScaleIsKept) {
  std::mt19937 rng(4);
  const BaProblem start = cameraRowOverPoints(rng);
  BaProblem corrected = start;
  corrected.poses[3].t_cw += Eigen::Vector3d(0.01, -0.02, 0.005);
  BaProblem solved = corrected;
  scaleAboutTheFixedCamera(solved, 3.0);
  const double s = restoreScale(solved, cameraCentres(start));
  EXPECT_NEAR(s * 3.0, 1.0, 0.01);  // the sums differ by the one camera's move
  // Shape: distances between cameras relative to each other as in `corrected`.
  const auto want = cameraCentres(corrected), got = cameraCentres(solved);
  const double ratio = (got[5] - got[0]).norm() / (want[5] - want[0]).norm();
  for (size_t i = 1; i < want.size(); ++i)
    EXPECT_NEAR((got[i] - got[0]).norm(), ratio * (want[i] - want[0]).norm(), 1e-9) << "camera " << i;
}

// Two fixed poses hold the scale themselves (local BA): nothing is changed.
TEST(ScaleGauge, AProblemWithTwoFixedPosesIsLeftAsItIs) {
  std::mt19937 rng(5);
  BaProblem pb = cameraRowOverPoints(rng);
  pb.poses[1].fixed = true;
  const BaProblem before = pb;
  auto centres = cameraCentres(pb);
  for (auto& c : centres) c *= 2.0;
  EXPECT_EQ(restoreScale(pb, centres), 1.0);
  for (size_t i = 0; i < pb.poses.size(); ++i) EXPECT_EQ(pb.poses[i].t_cw, before.poses[i].t_cw);
}

}  // namespace
}  // namespace hiveslam::core
