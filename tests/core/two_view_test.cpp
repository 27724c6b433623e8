// Two-view initialization on rendered images recovers the true motion up to scale.
#include <gtest/gtest.h>

#include <random>

#include "core/camera/pinhole_radtan.hpp"
#include "core/geometry/two_view.hpp"
#include "core/matching/initial_matcher.hpp"
#include "core/optim/bundle_adjustment.hpp"
#include "synth/renderer.hpp"
#include "synth/sequence.hpp"

namespace hiveslam::core {
namespace {

struct Views {
  Frame f1, f2;
  Eigen::Isometry3d T_21;  // true motion
  cv::Mat depth1;
};

Views render(const std::string& trajectory, int a, int b, uint64_t seed) {
  synth::SequenceOptions o;
  o.trajectory = trajectory;
  o.seed = seed;
  o.frames = 1000;
  const auto model = synth::buildSequence(o);
  const synth::RayTable rays(model.lens);
  const camera::PinholeRadTan cam(model.lens.width, model.lens.height, model.lens.fx, model.lens.fy, model.lens.cx,
                                  model.lens.cy);
  features::OrbExtractor orb;
  Views v;
  v.f1 = makeFrame(model.renderImage(a, rays), 0, model.stamp(a), orb, cam);
  v.f2 = makeFrame(model.renderImage(b, rays), 1, model.stamp(b), orb, cam);
  v.T_21 = model.pose(b).inverse() * model.pose(a);
  cv::Mat radiance;
  synth::renderRadiance(model.scene, rays, model.pose(a), radiance, &v.depth1);
  return v;
}

void expectRecovered(const Views& v) {
  const auto m = matchForInitialization(v.f1, v.f2);
  std::vector<Eigen::Vector2d> p1, p2;
  std::vector<size_t> which;
  for (size_t i = 0; i < m.size(); ++i)
    if (m[i] >= 0) {
      p1.push_back(v.f1.points[i]);
      p2.push_back(v.f2.points[static_cast<size_t>(m[i])]);
      which.push_back(i);
    }
  ASSERT_GT(p1.size(), 200u);
  TwoViewResult r = initializeTwoView(p1, p2, v.f1.K, {});
  ASSERT_TRUE(r.ok) << r.reason;
  const double raw_rot_err = Eigen::AngleAxisd(r.T_21.linear().transpose() * v.T_21.linear()).angle() * 180 / M_PI;
  EXPECT_LT(raw_rot_err, 1.5) << "linear two-view estimate";
  // The initial map is refined by full BA (first view fixed) before anything uses it.
  BaProblem ba;
  ba.K = v.f1.K;
  ba.poses.push_back({Eigen::Quaterniond::Identity(), Eigen::Vector3d::Zero(), true});
  ba.poses.push_back({Eigen::Quaterniond(r.T_21.linear()), r.T_21.translation(), false});
  for (size_t k = 0; k < p1.size(); ++k) {
    if (!r.good[k]) continue;
    const int id = static_cast<int>(ba.points.size());
    ba.points.push_back({r.points[k], false});
    const double w = 1.0 / v.f1.keypoints[which[k]].size * 31.0;
    ba.observations.push_back({0, id, p1[k], w});
    ba.observations.push_back({1, id, p2[k], w});
  }
  bundleAdjust(ba);
  const size_t n_points = ba.points.size();
  size_t j = 0;
  for (size_t k = 0; k < p1.size(); ++k)
    if (r.good[k]) r.points[k] = ba.points[j++].p_w;
  ASSERT_EQ(j, n_points);
  r.T_21.linear() = ba.poses[1].q_cw.toRotationMatrix();
  r.T_21.translation() = ba.poses[1].t_cw;
  // Fix the scale again: BA may move it, the checks below compare shapes.
  const double s = r.T_21.translation().norm();
  r.T_21.translation() /= s;
  for (auto& p : r.points) p /= s;
  const double rot_err = Eigen::AngleAxisd(r.T_21.linear().transpose() * v.T_21.linear()).angle() * 180 / M_PI;
  const double dir_err =
      std::acos(std::clamp(r.T_21.translation().normalized().dot(v.T_21.translation().normalized()), -1.0, 1.0)) * 180 / M_PI;
  EXPECT_LT(rot_err, 0.2) << r.model;
  EXPECT_LT(dir_err, 2.0) << r.model;
  EXPECT_GT(r.good_count, 100);
  // Scaled by the true baseline, triangulated depths match the rendered depth map.
  const double scale = v.T_21.translation().norm();
  std::vector<double> rel;
  for (size_t k = 0; k < which.size(); ++k) {
    if (!r.good[k]) continue;
    const auto& kp = v.f1.keypoints[which[k]];
    const double truth = v.depth1.at<float>(cvRound(kp.pt.y), cvRound(kp.pt.x));
    rel.push_back(std::abs(r.points[k].z() * scale - truth) / truth);
  }
  std::nth_element(rel.begin(), rel.begin() + rel.size() / 2, rel.end());
  EXPECT_LT(rel[rel.size() / 2], 0.03);
}

// Frame 100 of the loop faces mostly one wall: against frames 112-118 and 122 its two homography
// decompositions explain the matches equally well (within 2 of 329-437), the initializer refuses
// them as ambiguous and waits; against 120 the motion is unique.
TEST(TwoView, RecoversMotionOnTheLoop) { expectRecovered(render("loop", 100, 120, 1)); }
TEST(TwoView, RecoversMotionOnTheSweep) { expectRecovered(render("sweep", 300, 316, 4)); }

TEST(TwoView, RefusesPureRotation) {
  // Same position, turned by 4 degrees: no parallax, so no map may be made.
  Views v = render("loop", 100, 100, 1);
  synth::SequenceOptions o;
  o.frames = 1000;
  const auto model = synth::buildSequence(o);
  const synth::RayTable rays(model.lens);
  Eigen::Isometry3d T = model.pose(100);
  T.linear() = T.linear() * Eigen::AngleAxisd(4 * M_PI / 180, Eigen::Vector3d::UnitY()).toRotationMatrix();
  cv::Mat radiance;
  synth::renderRadiance(model.scene, rays, T, radiance);
  cv::Mat img;
  radiance.convertTo(img, CV_8U);
  const camera::PinholeRadTan cam(model.lens.width, model.lens.height, model.lens.fx, model.lens.fy, model.lens.cx,
                                  model.lens.cy);
  features::OrbExtractor orb;
  v.f2 = makeFrame(img, 1, 0, orb, cam);
  const auto m = matchForInitialization(v.f1, v.f2);
  std::vector<Eigen::Vector2d> p1, p2;
  for (size_t i = 0; i < m.size(); ++i)
    if (m[i] >= 0) {
      p1.push_back(v.f1.points[i]);
      p2.push_back(v.f2.points[static_cast<size_t>(m[i])]);
    }
  EXPECT_FALSE(initializeTwoView(p1, p2, v.f1.K, {}).ok);
}

// A road seen from a car through KITTI's camera: the road surface, two facades and distant
// points, 0.3 px of noise per coordinate. The second view has moved `forward_m` ahead and turned
// a little.
struct RoadMatches {
  std::vector<Eigen::Vector2d> p1, p2;
  Intrinsics K{707.09, 707.09, 601.89, 183.11};
  Eigen::Isometry3d T_21 = Eigen::Isometry3d::Identity();
};

RoadMatches roadScene(double forward_m, uint64_t seed) {
  RoadMatches m;
  std::mt19937 rng(static_cast<unsigned>(seed));
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::normal_distribution<double> noise(0.0, 0.3);
  m.T_21.linear() = (Eigen::AngleAxisd(0.3 * M_PI / 180, Eigen::Vector3d::UnitY()) *
                     Eigen::AngleAxisd(0.1 * M_PI / 180, Eigen::Vector3d::UnitX()))
                        .toRotationMatrix();
  m.T_21.translation() = -m.T_21.linear() * Eigen::Vector3d(0, 0, forward_m);
  while (m.p1.size() < 600) {
    Eigen::Vector3d X;
    const double kind = u(rng);
    if (kind < 0.4)
      X = {-6 + 12 * u(rng), 1.65, 3 + 22 * u(rng)};  // road, 1.65 m below the camera
    else if (kind < 0.8)
      X = {u(rng) < 0.5 ? -6.0 : 6.0, -4 + 5.65 * u(rng), 4 + 30 * u(rng)};  // facades
    else
      X = {-60 + 120 * u(rng), -20 + 20 * u(rng), 60 + 140 * u(rng)};  // far away
    const Eigen::Vector2d a = m.K.project(X), b = m.K.project(m.T_21 * X);
    const auto inside = [](const Eigen::Vector2d& q) { return q.x() >= 0 && q.y() >= 0 && q.x() < 1226 && q.y() < 370; };
    if (!inside(a) || !inside(b)) continue;
    m.p1.push_back(a + Eigen::Vector2d(noise(rng), noise(rng)));
    m.p2.push_back(b + Eigen::Vector2d(noise(rng), noise(rng)));
  }
  return m;
}

double rotationErrorDeg(const TwoViewResult& r, const Eigen::Isometry3d& truth) {
  return Eigen::AngleAxisd(r.T_21.linear().transpose() * truth.linear()).angle() * 180 / M_PI;
}

TEST(TwoView, NeverTakesParallaxFromARotationError) {
  // 9 cm ahead, as between KITTI 07's first two frames: most matches are too parallel to place.
  // A wrong homography decomposition, rotated 1 to 2 degrees off, used to "triangulate" nearly all
  // of them at that angle and win (6 of these 20 seeds). Either no map, or the true motion: the
  // linear estimate within 0.5 degrees (BA refines it; the false ones were 1.0-1.5 off).
  int made = 0;
  for (uint64_t seed = 1; seed <= 20; ++seed) {
    const RoadMatches m = roadScene(0.09, seed);
    TwoViewOptions o;
    o.seed = seed;
    const TwoViewResult r = initializeTwoView(m.p1, m.p2, m.K, o);
    if (!r.ok) continue;
    ++made;
    EXPECT_LT(rotationErrorDeg(r, m.T_21), 0.5) << "seed " << seed << ", " << r.model;
  }
  RecordProperty("maps_made", made);
}

TEST(TwoView, RecoversTheRoadOnABaselineItCanResolve) {
  // 1.5 m ahead: a median parallax just above the 1 degree the initializer asks for.
  for (uint64_t seed = 1; seed <= 5; ++seed) {
    const RoadMatches m = roadScene(1.5, seed);
    TwoViewOptions o;
    o.seed = seed;
    const TwoViewResult r = initializeTwoView(m.p1, m.p2, m.K, o);
    ASSERT_TRUE(r.ok) << "seed " << seed << ": " << r.reason;
    EXPECT_LT(rotationErrorDeg(r, m.T_21), 0.5) << "seed " << seed;
    const double dir_err =
        std::acos(std::clamp(r.T_21.translation().normalized().dot(m.T_21.translation().normalized()), -1.0, 1.0)) * 180 / M_PI;
    EXPECT_LT(dir_err, 5.0) << "seed " << seed;
  }
}

TEST(TwoView, MakesAMapWhereAMajorityOfTheMatchesAgree) {
  // RANSAC's iterations are capped (TwoViewOptions) so that a lost tracker's hopeless attempts
  // stay short; a pair where 65% of the matches are right must still give the motion.
  for (uint64_t seed = 1; seed <= 10; ++seed) {
    RoadMatches m = roadScene(3.0, seed);
    std::mt19937 rng(static_cast<unsigned>(seed));
    std::uniform_real_distribution<double> x(0, 1226), y(0, 370);
    for (size_t i = 0; i < m.p2.size(); ++i)
      if (i % 20 < 7) m.p2[i] = {x(rng), y(rng)};
    TwoViewOptions o;
    o.seed = seed;
    const TwoViewResult r = initializeTwoView(m.p1, m.p2, m.K, o);
    ASSERT_TRUE(r.ok) << "seed " << seed << ": " << r.reason;
    EXPECT_LT(rotationErrorDeg(r, m.T_21), 0.5) << "seed " << seed;
  }
}

}  // namespace
}  // namespace hiveslam::core
