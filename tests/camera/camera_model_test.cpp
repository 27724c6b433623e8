#include <gtest/gtest.h>

#include <opencv2/calib3d.hpp>

#include "core/camera/kannala_brandt.hpp"
#include "core/camera/pinhole_radtan.hpp"

namespace hiveslam::camera {
namespace {

// EuRoC cam0 and TUM-VI cam0 calibrations: the two lens families the project reads.
PinholeRadTan euroc() {
  return PinholeRadTan(752, 480, 458.654, 457.296, 367.215, 248.375,
                       {-0.28340811, 0.07395907, 0.00019359, 1.76187114e-05});
}
KannalaBrandt tumvi() {
  return KannalaBrandt(512, 512, 190.97847715128717, 190.9733070521226, 254.93170605935475,
                       256.8974428996504,
                       {0.0034823894022493434, 0.0007150348452162257, -0.0020532361418706202,
                        0.00020293673591811182});
}

void expectRoundTrip(const CameraModel& cam, double tolerance_px) {
  for (int v = 0; v < cam.height(); v += 7)
    for (int u = 0; u < cam.width(); u += 7) {
      const Eigen::Vector2d uv(u + 0.25, v + 0.75);
      const Eigen::Vector3d bearing = cam.unproject(uv);
      EXPECT_NEAR(bearing.norm(), 1.0, 1e-12);
      Eigen::Vector2d back;
      ASSERT_TRUE(cam.project(bearing * 3.7, back));
      ASSERT_LT((back - uv).norm(), tolerance_px) << "pixel " << u << "," << v;
    }
}

TEST(PinholeRadTan, ProjectUnprojectRoundTripOverTheImage) { expectRoundTrip(euroc(), 1e-7); }

TEST(KannalaBrandt, ProjectUnprojectRoundTripOverTheImage) { expectRoundTrip(tumvi(), 1e-7); }

TEST(PinholeRadTan, DistortionMatchesOpenCv) {
  const PinholeRadTan cam = euroc();
  const auto p = cam.parameters();
  cv::Mat K = (cv::Mat_<double>(3, 3) << p[0], 0, p[2], 0, p[1], p[3], 0, 0, 1);
  cv::Mat D = (cv::Mat_<double>(1, 5) << p[4], p[5], p[6], p[7], p[8]);
  std::vector<cv::Point3d> pts;
  for (double x = -1.5; x <= 1.5; x += 0.25)
    for (double y = -1.0; y <= 1.0; y += 0.25) pts.emplace_back(x, y, 2.0);
  std::vector<cv::Point2d> expected;
  cv::projectPoints(pts, cv::Vec3d(0, 0, 0), cv::Vec3d(0, 0, 0), K, D, expected);
  for (size_t i = 0; i < pts.size(); ++i) {
    Eigen::Vector2d uv;
    ASSERT_TRUE(cam.project({pts[i].x, pts[i].y, pts[i].z}, uv));
    EXPECT_NEAR(uv.x(), expected[i].x, 1e-9);
    EXPECT_NEAR(uv.y(), expected[i].y, 1e-9);
  }
}

TEST(KannalaBrandt, MatchesOpenCvFisheye) {
  const KannalaBrandt cam = tumvi();
  const auto p = cam.parameters();
  cv::Matx33d K(p[0], 0, p[2], 0, p[1], p[3], 0, 0, 1);
  cv::Vec4d D(p[4], p[5], p[6], p[7]);
  std::vector<cv::Point3d> pts;
  for (double x = -2.0; x <= 2.0; x += 0.5)
    for (double y = -2.0; y <= 2.0; y += 0.5) pts.emplace_back(x, y, 1.0);
  std::vector<cv::Point2d> expected;
  cv::fisheye::projectPoints(pts, expected, cv::Vec3d(0, 0, 0), cv::Vec3d(0, 0, 0), K, D);
  for (size_t i = 0; i < pts.size(); ++i) {
    Eigen::Vector2d uv;
    ASSERT_TRUE(cam.project({pts[i].x, pts[i].y, pts[i].z}, uv));
    EXPECT_NEAR(uv.x(), expected[i].x, 1e-7);
    EXPECT_NEAR(uv.y(), expected[i].y, 1e-7);
  }
}

TEST(KannalaBrandt, ImagesPointsBeyondNinetyDegrees) {
  const KannalaBrandt cam = tumvi();
  Eigen::Vector2d uv;
  // 100 degrees off axis: behind the image plane, still inside a fisheye's view.
  const double a = 100.0 * M_PI / 180.0;
  ASSERT_TRUE(cam.project({std::sin(a), 0.0, std::cos(a)}, uv));
  const Eigen::Vector3d back = cam.unproject(uv);
  EXPECT_NEAR(std::acos(back.z()), a, 1e-9);
}

TEST(PinholeRadTan, RejectsPointsBehindTheCamera) {
  Eigen::Vector2d uv;
  EXPECT_FALSE(euroc().project({0.1, 0.2, -1.0}, uv));
}

TEST(CameraModels, RejectWrongCoefficientCounts) {
  EXPECT_THROW(PinholeRadTan(10, 10, 5, 5, 5, 5, {0.1, 0.2, 0.3}), std::invalid_argument);
  EXPECT_THROW(KannalaBrandt(10, 10, 5, 5, 5, 5, {0.1}), std::invalid_argument);
}

TEST(PinholeRadTan, UndistortedCameraIsLinear) {
  const PinholeRadTan cam(640, 480, 500, 500, 320, 240);
  Eigen::Vector2d uv;
  ASSERT_TRUE(cam.project({0.2, -0.1, 2.0}, uv));
  EXPECT_NEAR(uv.x(), 320 + 500 * 0.1, 1e-12);
  EXPECT_NEAR(uv.y(), 240 - 500 * 0.05, 1e-12);
}

}  // namespace
}  // namespace hiveslam::camera
