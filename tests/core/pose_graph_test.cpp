#include <gtest/gtest.h>

#include <cmath>

#include "core/optim/pose_graph.hpp"

namespace hiveslam::core {
namespace {

// A camera going once around a circle of radius 2 m. Odometry measured with a drift (each step
// 1% too long and turning 0.3 degrees too much), so that chaining it leaves a gap at the end;
// one loop edge measured from the truth closes it. Optimization must remove most of the error.
TEST(PoseGraph, ClosesASyntheticDriftedLoop) {
  const int n = 40;
  std::vector<Sim3> truth;  // S_iw
  for (int i = 0; i < n; ++i) {
    const double a = 2 * M_PI * i / n;
    Eigen::Isometry3d T_wc = Eigen::Isometry3d::Identity();
    T_wc.linear() = Eigen::AngleAxisd(a, Eigen::Vector3d::UnitY()).toRotationMatrix();
    T_wc.translation() = Eigen::Vector3d(2 * std::cos(a), 0, 2 * std::sin(a));
    truth.push_back(Sim3(T_wc.inverse()));
  }
  const Sim3 drift(Eigen::Quaterniond(Eigen::AngleAxisd(0.3 * M_PI / 180, Eigen::Vector3d::UnitY())),
                   Eigen::Vector3d(0.01, 0, 0), 1.01);
  PoseGraph g;
  g.poses.push_back(truth[0]);
  g.fixed.push_back(true);
  for (int i = 1; i < n; ++i) {
    const Sim3 measured = drift * (truth[static_cast<size_t>(i)] * truth[static_cast<size_t>(i - 1)].inverse());
    g.edges.push_back({i, i - 1, measured, 1.0});
    g.poses.push_back(measured * g.poses.back());
    g.fixed.push_back(false);
  }
  g.edges.push_back({0, n - 1, truth[0] * truth[static_cast<size_t>(n - 1)].inverse(), 1.0});

  auto centreError = [&](const std::vector<Sim3>& poses) {
    double worst = 0;
    for (int i = 0; i < n; ++i) {
      const Eigen::Vector3d c = poses[static_cast<size_t>(i)].inverse().t;
      const Eigen::Vector3d c_true = truth[static_cast<size_t>(i)].inverse().t;
      worst = std::max(worst, (c - c_true).norm());
    }
    return worst;
  };
  const double before = centreError(g.poses);
  const PoseGraphSummary s = optimizePoseGraph(g, 50);
  const double after = centreError(g.poses);
  EXPECT_GT(before, 0.3);
  EXPECT_LT(after, before / 5);
  EXPECT_LT(s.final_cost, s.initial_cost / 100);
  // The fixed pose did not move.
  EXPECT_LT((g.poses[0].t - truth[0].t).norm(), 1e-9);
}

}  // namespace
}  // namespace hiveslam::core
