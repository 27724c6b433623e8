#include <gtest/gtest.h>

#include <random>

#include "core/optim/pose_optimizer.hpp"

namespace hiveslam::core {
namespace {

// Under either loss: tracking's Huber and the end-of-run refinement's Cauchy.
void recoversPoseAndRejectsInjectedOutliers(const PoseLoss& loss) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1, 1);
  std::normal_distribution<double> n(0, 0.7);
  const Intrinsics K{450, 450, 376, 240};
  Eigen::Isometry3d truth = Eigen::Isometry3d::Identity();
  truth.linear() = Eigen::AngleAxisd(0.2, Eigen::Vector3d(0.1, 1, 0.2).normalized()).toRotationMatrix();
  truth.translation() = Eigen::Vector3d(0.3, -0.1, 0.2);
  std::vector<PoseObservation> obs;
  std::vector<bool> injected;
  for (int i = 0; i < 200; ++i) {
    const Eigen::Vector3d pc(2 * u(rng), 1.5 * u(rng), 3 + 2 * u(rng));
    PoseObservation o{truth.inverse() * pc, K.project(pc) + Eigen::Vector2d(n(rng), n(rng)), 1.0};
    const bool bad = i % 5 == 0;  // 20% wrong matches, 15-60 px off
    if (bad) o.uv += Eigen::Vector2d(15 + 45 * std::abs(u(rng)), 20 * u(rng));
    obs.push_back(o);
    injected.push_back(bad);
  }
  Eigen::Isometry3d T = truth;
  T.translation() += Eigen::Vector3d(0.08, 0.05, -0.06);
  T.linear() = T.linear() * Eigen::AngleAxisd(0.05, Eigen::Vector3d::UnitX()).toRotationMatrix();
  std::vector<bool> outlier;
  const int inliers = optimizePose(K, obs, T, outlier, loss);
  EXPECT_LT((T.translation() - truth.translation()).norm(), 0.01);
  EXPECT_LT(Eigen::AngleAxisd(T.linear().transpose() * truth.linear()).angle(), 0.003);
  int caught = 0, false_alarms = 0;
  for (size_t i = 0; i < obs.size(); ++i) {
    caught += outlier[i] && injected[i];
    false_alarms += outlier[i] && !injected[i];
  }
  EXPECT_EQ(caught, 40);
  EXPECT_LE(false_alarms, 8);
  EXPECT_EQ(inliers, static_cast<int>(obs.size()) - caught - false_alarms);
}

TEST(PoseOptimizer, RecoversPoseAndRejectsInjectedOutliersUnderHuber) { recoversPoseAndRejectsInjectedOutliers({}); }

TEST(PoseOptimizer, RecoversPoseAndRejectsInjectedOutliersUnderCauchy) {
  recoversPoseAndRejectsInjectedOutliers(PoseLoss::cauchy());
}

}  // namespace
}  // namespace hiveslam::core
