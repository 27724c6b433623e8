#include "core/map/point_normals.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace hiveslam::core {
namespace {

double angleDeg(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::acos(std::min(1.0, std::abs(a.normalized().dot(b.normalized())))) * 180.0 / M_PI;
}

// Two faces of a box: 400 points on a wall x = 0 (first), 400 on a floor z = 0, each a metre
// square, noisy by `noise_sd` metres across its face.
std::vector<Eigen::Vector3d> wallAndFloor(std::mt19937& rng, double noise_sd) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::normal_distribution<double> noise(0.0, noise_sd);
  std::vector<Eigen::Vector3d> points;
  for (int i = 0; i < 400; ++i) points.emplace_back(noise(rng), u(rng), u(rng));
  for (int i = 0; i < 400; ++i) points.emplace_back(u(rng), u(rng), noise(rng));
  return points;
}

// The two faces, points 5 mm noisy, and a loose cloud.
TEST(PlaneNormals, FindTheFacesOfABoxAndNoneInACloud) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<Eigen::Vector3d> points = wallAndFloor(rng, 0.005);
  for (int i = 0; i < 100; ++i) points.emplace_back(5 + u(rng), 5 + u(rng), 5 + u(rng));  // cloud
  const auto normals = planeNormals(points);
  int wall = 0, floor = 0, cloud = 0, wall_far = 0, floor_far = 0;
  for (size_t i = 0; i < points.size(); ++i) {
    const Eigen::Vector3d& p = points[i];
    if (i < 800) {
      const bool on_wall = i < 400;
      // Away from the shared edge (x = 0, z = 0) a point's neighbours lie on its own face.
      if ((on_wall ? p.z() : p.x()) < 0.25) continue;
      (on_wall ? wall_far : floor_far) += 1;
      if (!normals[i]) continue;
      const double off = angleDeg(*normals[i], on_wall ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitZ());
      EXPECT_LT(off, 6.0) << i;
      (on_wall ? wall : floor) += off < 6.0;
    } else {
      cloud += normals[i].has_value();
    }
  }
  EXPECT_GT(wall, 0.9 * wall_far);
  EXPECT_GT(floor, 0.9 * floor_far);
  EXPECT_LT(cloud, 10);
}

// Near the edge a point's neighbours lie on both faces: a plane fitted to all of them is neither
// face (and a flatness test then leaves the point without one). By consensus it gets a face.
TEST(PlaneNormals, NearAnEdgeAPointGetsAFaceNotAPlaneBetween) {
  std::mt19937 rng(5);
  const std::vector<Eigen::Vector3d> points = wallAndFloor(rng, 0.002);
  const auto normals = planeNormals(points);
  int near = 0, face = 0;
  for (size_t i = 0; i < points.size(); ++i) {
    const Eigen::Vector3d& p = points[i];
    if ((i < 400 ? p.z() : p.x()) > 0.08 || p.y() < 0.1 || p.y() > 0.9) continue;
    ++near;
    if (!normals[i]) continue;
    // A plane between the faces is 45 degrees off both; the refit's band reaches the other face's
    // nearest points and may tilt a face a few degrees.
    const double off = std::min(angleDeg(*normals[i], Eigen::Vector3d::UnitX()), angleDeg(*normals[i], Eigen::Vector3d::UnitZ()));
    EXPECT_LT(off, 10.0) << i;
    face += off < 10.0;
  }
  ASSERT_GT(near, 50);
  EXPECT_GT(face, 0.9 * near);
}

TEST(PlaneNormals, TooFewPointsGiveNone) {
  const std::vector<Eigen::Vector3d> few{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  for (const auto& n : planeNormals(few)) EXPECT_FALSE(n);
}

}  // namespace
}  // namespace hiveslam::core
