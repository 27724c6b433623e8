#include <gtest/gtest.h>

#include <random>

#include "core/optim/bundle_adjustment.hpp"

namespace hiveslam::core {
namespace {

// Five cameras on an arc looking at a cloud of points; the first two are fixed (gauge and
// scale), the others and all points are perturbed, and 5% of observations are gross outliers.
TEST(BundleAdjustment, RecoversPerturbedPosesAndPointsAndFlagsOutliers) {
  std::mt19937 rng(42);
  std::normal_distribution<double> n(0, 1);
  std::uniform_real_distribution<double> u(-1, 1);
  BaProblem pb;
  pb.K = {450, 450, 376, 240};
  std::vector<BaPose> truth_poses;
  for (int c = 0; c < 5; ++c) {
    const Eigen::Matrix3d R = Eigen::AngleAxisd(-0.1 * c, Eigen::Vector3d::UnitY()).toRotationMatrix();
    const Eigen::Vector3d centre(0.3 * c, 0.02 * c, 0);
    truth_poses.push_back({Eigen::Quaterniond(R.transpose()), -(R.transpose() * centre), c < 2});
  }
  std::vector<Eigen::Vector3d> truth_points;
  for (int i = 0; i < 300; ++i) truth_points.emplace_back(1.5 * u(rng) + 0.6, u(rng), 4 + u(rng));
  int outliers = 0;
  std::vector<bool> injected;
  for (int c = 0; c < 5; ++c)
    for (int i = 0; i < 300; ++i) {
      const auto& P = truth_poses[static_cast<size_t>(c)];
      const Eigen::Vector3d pc = P.q_cw * truth_points[static_cast<size_t>(i)] + P.t_cw;
      Eigen::Vector2d uv = pb.K.project(pc) + 0.5 * Eigen::Vector2d(n(rng), n(rng));
      const bool bad = (i * 7 + c) % 20 == 0;
      if (bad) {
        uv += Eigen::Vector2d(30 + 20 * u(rng), -25);
        ++outliers;
      }
      injected.push_back(bad);
      pb.observations.push_back({c, i, uv, 1.0});
    }
  pb.poses = truth_poses;
  for (size_t c = 2; c < 5; ++c) {
    pb.poses[c].t_cw += Eigen::Vector3d(0.05, -0.04, 0.06);
    pb.poses[c].q_cw = pb.poses[c].q_cw * Eigen::Quaterniond(Eigen::AngleAxisd(0.03, Eigen::Vector3d(1, 1, 0).normalized()));
  }
  for (const auto& p : truth_points) pb.points.push_back({p + 0.05 * Eigen::Vector3d(n(rng), n(rng), n(rng)), false});

  auto poseError = [&]() {
    double e = 0;
    for (size_t c = 2; c < 5; ++c) e += (pb.poses[c].t_cw - truth_poses[c].t_cw).norm();
    return e;
  };
  const double before = poseError();
  const BaSummary s = bundleAdjust(pb, {30, 2.447, nullptr, true});
  EXPECT_LT(s.final_cost, s.initial_cost);
  EXPECT_LT(poseError(), before / 20) << before << " -> " << poseError();
  for (size_t c = 0; c < 2; ++c) EXPECT_EQ(pb.poses[c].t_cw, truth_poses[c].t_cw);  // fixed stay put
  int flagged_right = 0, flagged_wrong = 0;
  for (size_t i = 0; i < injected.size(); ++i) {
    if (s.outlier[i] && injected[i]) ++flagged_right;
    if (s.outlier[i] && !injected[i]) ++flagged_wrong;
  }
  EXPECT_EQ(flagged_right, outliers);
  EXPECT_LT(flagged_wrong, static_cast<int>(injected.size()) / 50);  // a few 95% tails
}

TEST(BundleAdjustment, StopsWhenAborted) {
  BaProblem pb;
  pb.K = {450, 450, 376, 240};
  pb.poses.push_back({});
  pb.poses.back().fixed = true;
  pb.points.push_back({{0, 0, 5}, false});
  pb.observations.push_back({0, 0, {380, 250}, 1.0});
  std::atomic<bool> abort{true};
  const BaSummary s = bundleAdjust(pb, {50, 2.447, &abort, true});
  EXPECT_LE(s.iterations, 2);
}

}  // namespace
}  // namespace hiveslam::core
