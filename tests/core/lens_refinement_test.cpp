#include <gtest/gtest.h>

#include <random>

#include "core/optim/lens_refinement.hpp"

namespace hiveslam::core {
namespace {

// The realistic renders' lens (synth::Imaging::realistic): 2% and 2.4% longer than the nominal
// 525, the principal point 4 and -3 px off, and a radial k1 of 0.05 that sensor.yaml leaves out.
constexpr LensParameters kNominal{525, 525, 319.5, 239.5, 0};
constexpr LensParameters kTrue{535.5, 537.6, 323.5, 236.5, 0.05};

Eigen::Vector2d project(const LensParameters& l, const Eigen::Vector3d& pc) {
  const double x = pc.x() / pc.z(), y = pc.y() / pc.z(), d = 1 + l.k1 * (x * x + y * y);
  return {l.fx * x * d + l.cx, l.fy * y * d + l.cy};
}

// A hand-held sweep past the walls of a 6 x 5 m room: 30 keyframes turning through 70 degrees,
// nodding by up to 17, and walking 1.5 m; 1000 points on the walls, each keypoint half a pixel
// off.
BaProblem sweep(std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-1, 1);
  std::normal_distribution<double> noise(0, 0.5);
  BaProblem ba;
  for (int k = 0; k < 30; ++k) {
    Eigen::Isometry3d T_wc = Eigen::Isometry3d::Identity();
    T_wc.linear() = (Eigen::AngleAxisd(-0.6 + k * 1.2 / 29, Eigen::Vector3d::UnitY()) *
                     Eigen::AngleAxisd(0.3 * std::sin(0.7 * k), Eigen::Vector3d::UnitX()))
                        .toRotationMatrix();
    T_wc.translation() = Eigen::Vector3d(-0.75 + 0.05 * k, 0.05 * std::cos(k), 0.1 * std::sin(0.5 * k));
    const Eigen::Isometry3d T_cw = T_wc.inverse();
    ba.poses.push_back({Eigen::Quaterniond(T_cw.linear()), T_cw.translation(), false});
  }
  for (int i = 0; i < 1000; ++i) {
    // On the far wall (z = 2.5) or a side wall (x = +-3), at heights of +-1.2 m.
    Eigen::Vector3d p;
    if (i % 3 == 0) p = Eigen::Vector3d(3.0 * u(rng), 1.2 * u(rng), 2.5);
    else p = Eigen::Vector3d(i % 3 == 1 ? 3.0 : -3.0, 1.2 * u(rng), 2.5 * std::abs(u(rng)));
    const int index = static_cast<int>(ba.points.size());
    std::vector<BaObservation> seen;
    for (size_t k = 0; k < ba.poses.size(); ++k) {
      const Eigen::Vector3d pc = ba.poses[k].T_cw() * p;
      if (pc.z() < 0.3) continue;
      const Eigen::Vector2d uv = project(kTrue, pc) + Eigen::Vector2d(noise(rng), noise(rng));
      if (uv.x() < 0 || uv.y() < 0 || uv.x() >= 640 || uv.y() >= 480) continue;
      seen.push_back({static_cast<int>(k), index, uv, 1.0});
    }
    if (seen.size() < 2) continue;
    ba.points.push_back({p, false});
    ba.observations.insert(ba.observations.end(), seen.begin(), seen.end());
  }
  return ba;
}

TEST(LensRefinement, FindsTheLensTheKeypointsWereSeenWith) {
  std::mt19937 rng(3);
  BaProblem ba = sweep(rng);
  // The map as the nominal lens left it: every pose but the two held ones and every point moved.
  std::normal_distribution<double> n(0, 1);
  for (size_t k = 2; k < ba.poses.size(); ++k) ba.poses[k].t_cw += 0.02 * Eigen::Vector3d(n(rng), n(rng), n(rng));
  for (BaPoint& p : ba.points) p.p_w += 0.03 * Eigen::Vector3d(n(rng), n(rng), n(rng));
  const LensRefinement r = refineLens(ba, kNominal);
  EXPECT_GT(r.rms_before_px, 3.0);
  EXPECT_LT(r.rms_after_px, 0.8);
  // Half a percent: a fifth of the nominal lens's error (the focal length trades a little
  // against the depths, 0.2-0.4% at this noise).
  EXPECT_NEAR(r.lens.fx, kTrue.fx, 0.005 * kTrue.fx);
  EXPECT_NEAR(r.lens.fy, kTrue.fy, 0.005 * kTrue.fy);
  EXPECT_NEAR(r.lens.cx, kTrue.cx, 1.5);
  EXPECT_NEAR(r.lens.cy, kTrue.cy, 1.5);
  EXPECT_NEAR(r.lens.k1, kTrue.k1, 0.005);
}

TEST(LensRefinement, LeavesAnExactLensWhereItIs) {
  std::mt19937 rng(5);
  const BaProblem ba = sweep(rng);
  const LensRefinement r = refineLens(ba, kTrue);
  EXPECT_NEAR(r.lens.fx, kTrue.fx, 0.005 * kTrue.fx);
  EXPECT_NEAR(r.lens.fy, kTrue.fy, 0.005 * kTrue.fy);
  EXPECT_NEAR(r.lens.k1, kTrue.k1, 0.003);
  EXPECT_LT(r.rms_after_px, 0.8);
}

TEST(LensRefinement, WantsEnoughOfAMap) {
  BaProblem ba;
  ba.poses.resize(2);
  const LensRefinement r = refineLens(ba, kNominal);
  EXPECT_EQ(r.observations, 0);
  EXPECT_EQ(r.lens.fx, kNominal.fx);
}

}  // namespace
}  // namespace hiveslam::core
