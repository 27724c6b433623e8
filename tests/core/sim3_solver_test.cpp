#include <gtest/gtest.h>

#include <random>

#include "core/geometry/sim3_solver.hpp"
#include "core/optim/sim3_refine.hpp"

namespace hiveslam::core {
namespace {

// Matched points seen from two cameras related by a known similarity (scale 1.7, as monocular
// maps built at different scales are), 0.5 px noise, 30% of the matches wrong.
TEST(Sim3Solver, RansacRecoversAKnownSimilarityDespiteOutliers) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-1, 1);
  std::normal_distribution<double> noise(0, 0.5);
  const Intrinsics K{450, 450, 376, 240};
  const Sim3 truth(Eigen::Quaterniond(Eigen::AngleAxisd(0.3, Eigen::Vector3d(0.2, 1, 0.1).normalized())),
                   Eigen::Vector3d(0.4, -0.1, 0.3), 1.7);
  std::vector<Sim3Match> matches;
  std::vector<bool> wrong;
  for (int i = 0; i < 120; ++i) {
    Sim3Match m;
    m.p2 = Eigen::Vector3d(1.5 * u(rng), 1.0 * u(rng), 3 + u(rng));
    m.p1 = truth * m.p2;
    const bool bad = i % 10 < 3;
    if (bad) m.p1 = Eigen::Vector3d(2 * u(rng), 1.5 * u(rng), 5 + 2 * u(rng));  // another point
    m.uv1 = K.project(m.p1) + Eigen::Vector2d(noise(rng), noise(rng));
    m.uv2 = K.project(m.p2) + Eigen::Vector2d(noise(rng), noise(rng));
    // The 3D points carry the map's error too (a few percent of depth).
    m.p1 *= 1 + 0.01 * u(rng);
    m.p2 *= 1 + 0.01 * u(rng);
    matches.push_back(m);
    wrong.push_back(bad);
  }
  const Sim3Result r = solveSim3Ransac(K, K, matches);
  ASSERT_TRUE(r.found);
  EXPECT_NEAR(r.S12.s, truth.s, 0.05);
  int false_inliers = 0, true_inliers = 0;
  for (size_t i = 0; i < matches.size(); ++i) {
    false_inliers += r.inlier[i] && wrong[i];
    true_inliers += r.inlier[i] && !wrong[i];
  }
  EXPECT_EQ(false_inliers, 0);
  EXPECT_GE(true_inliers, 75);

  // Refinement on the reprojection errors brings it to the noise level.
  Sim3 S = r.S12;
  std::vector<bool> inlier = r.inlier;
  const int refined = refineSim3(K, K, matches, S, inlier);
  EXPECT_GE(refined, 75);
  EXPECT_NEAR(S.s, truth.s, 0.02);
  EXPECT_LT((S.t - truth.t).norm(), 0.03);
  EXPECT_LT(S.q.angularDistance(truth.q), 0.005);
  EXPECT_NEAR(pointScale(matches, S, inlier), truth.s, 0.01);
}

// A place seen again from where it was seen before: the cameras stand together, and every
// scale projects the same. The refinement cannot find it; the points can.
TEST(Sim3Solver, ThePointsTellTheScaleWhereTheReprojectionsCannot) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1, 1);
  const Intrinsics K{450, 450, 376, 240};
  const Sim3 truth(Eigen::Quaterniond(Eigen::AngleAxisd(0.05, Eigen::Vector3d::UnitY())), Eigen::Vector3d::Zero(), 1.03);
  std::vector<Sim3Match> matches;
  for (int i = 0; i < 100; ++i) {
    Sim3Match m;
    m.p2 = Eigen::Vector3d(1.5 * u(rng), u(rng), 3 + u(rng));
    m.p1 = truth * m.p2;
    m.uv1 = K.project(m.p1);
    m.uv2 = K.project(m.p2);
    m.p1 *= 1 + 0.01 * u(rng);
    m.p2 *= 1 + 0.01 * u(rng);
    matches.push_back(m);
  }
  Sim3 S = truth;
  S.s = 1.12;  // where a refinement can wander off to
  std::vector<bool> inlier(matches.size(), true);
  EXPECT_EQ(refineSim3(K, K, matches, S, inlier), 100);
  EXPECT_GT(std::abs(S.s - truth.s), 0.05) << "the reprojections pinned the scale after all";
  EXPECT_NEAR(pointScale(matches, S, inlier), truth.s, 0.005);
}

// The points of a consistent pair of maps agree on one scale; where half of one side sits at a
// third of its depth, the median is no scale the two share, and the agreement says so.
TEST(Sim3Solver, ThePointsAgreeOnTheScaleOnlyWhereBothMapsAreConsistent) {
  std::mt19937 rng(4);
  std::uniform_real_distribution<double> u(-1, 1);
  const Sim3 truth(Eigen::Quaterniond(Eigen::AngleAxisd(0.1, Eigen::Vector3d::UnitY())), Eigen::Vector3d(0.2, 0, 0), 1.05);
  std::vector<Sim3Match> matches;
  for (int i = 0; i < 100; ++i) {
    Sim3Match m;
    m.p2 = Eigen::Vector3d(1.5 * u(rng), u(rng), 3 + u(rng));
    m.p1 = (truth * m.p2) * (1 + 0.03 * u(rng));
    m.uv1 = m.uv2 = Eigen::Vector2d::Zero();  // only the points are asked
    matches.push_back(m);
  }
  std::vector<bool> inlier(matches.size(), true);
  Sim3 S = truth;
  S.s = pointScale(matches, S, inlier);
  EXPECT_NEAR(S.s, truth.s, 0.02);
  EXPECT_DOUBLE_EQ(pointScaleAgreement(matches, S, inlier, 0.2), 1.0);
  for (size_t i = 0; i < matches.size(); i += 2) matches[i].p1 = S.t + 0.35 * (matches[i].p1 - S.t);
  S.s = pointScale(matches, S, inlier);
  EXPECT_LT(pointScaleAgreement(matches, S, inlier, 0.2), 0.6);
}

TEST(Sim3Solver, RefusesMatchesWithoutACommonSimilarity) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-1, 1);
  const Intrinsics K{450, 450, 376, 240};
  std::vector<Sim3Match> matches;
  for (int i = 0; i < 60; ++i) {
    Sim3Match m;
    m.p1 = Eigen::Vector3d(1.5 * u(rng), u(rng), 3 + u(rng));
    m.p2 = Eigen::Vector3d(1.5 * u(rng), u(rng), 3 + u(rng));
    m.uv1 = K.project(m.p1);
    m.uv2 = K.project(m.p2);
    matches.push_back(m);
  }
  EXPECT_FALSE(solveSim3Ransac(K, K, matches).found);
}

}  // namespace
}  // namespace hiveslam::core
