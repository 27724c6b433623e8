#include <gtest/gtest.h>

#include <random>

#include "eval/similarity.hpp"

namespace hiveslam::eval {
namespace {

TEST(Umeyama, RecoversAKnownSimilarityExactly) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-5, 5);
  Similarity truth;
  truth.scale = 2.7;
  truth.rotation = Eigen::AngleAxisd(1.1, Eigen::Vector3d(0.3, -0.5, 0.8).normalized()).toRotationMatrix();
  truth.translation = Eigen::Vector3d(1.5, -3.0, 0.25);
  Eigen::Matrix3Xd from(3, 50), to(3, 50);
  for (int i = 0; i < 50; ++i) {
    from.col(i) = Eigen::Vector3d(u(rng), u(rng), u(rng));
    to.col(i) = truth * Eigen::Vector3d(from.col(i));
  }
  const Similarity s = umeyama(from, to, true);
  EXPECT_NEAR(s.scale, truth.scale, 1e-12);
  EXPECT_LT((s.rotation - truth.rotation).norm(), 1e-12);
  EXPECT_LT((s.translation - truth.translation).norm(), 1e-12);
  EXPECT_NEAR(s.rotation.determinant(), 1.0, 1e-12);
}

TEST(Umeyama, WithoutScaleKeepsScaleOne) {
  Eigen::Matrix3Xd from(3, 4), to(3, 4);
  from << 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1;
  const Eigen::Matrix3d R = Eigen::AngleAxisd(0.4, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  to = (R * from).colwise() + Eigen::Vector3d(1, 2, 3);
  const Similarity s = umeyama(from, to, false);
  EXPECT_DOUBLE_EQ(s.scale, 1.0);
  EXPECT_LT((s.rotation - R).norm(), 1e-12);
}

TEST(Umeyama, ReflectionIsNotAllowed) {
  // A mirrored point set: the best proper rotation, never a reflection.
  Eigen::Matrix3Xd from(3, 4), to(3, 4);
  from << 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1;
  to = from;
  to.row(0) *= -1;
  EXPECT_NEAR(umeyama(from, to, true).rotation.determinant(), 1.0, 1e-12);
}

TEST(Similarity, AppliesToPoses) {
  Similarity s;
  s.scale = 2;
  s.rotation = Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  s.translation = Eigen::Vector3d(0, 0, 1);
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translation() = Eigen::Vector3d(1, 0, 0);
  const Eigen::Isometry3d out = s.apply(T);
  EXPECT_LT((out.translation() - Eigen::Vector3d(0, 2, 1)).norm(), 1e-12);
  EXPECT_LT((out.linear() - s.rotation).norm(), 1e-12);
}

}  // namespace
}  // namespace hiveslam::eval
