// The renderer is the oracle the SLAM core is tested against, so it is checked against
// independent code: the core's camera models and analytic geometry.
#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include "core/camera/pinhole_radtan.hpp"
#include "synth/renderer.hpp"

namespace hiveslam::synth {
namespace {

// An empty 10 x 10 x 3 m room whose +x wall is white with one black square of side `side`
// centred at world (5, 0, 1.5); every other surface mid grey.
Scene squareRoom(double side) {
  Scene s;
  s.room_min = {-5, -5, 0};
  s.room_max = {5, 5, 3};
  constexpr double density = 400.0;
  for (int i = 0; i < 6; ++i) {
    const double w = i < 4 ? 10.0 : 10.0, h = i < 4 ? 3.0 : 10.0;
    cv::Mat tex(static_cast<int>(h * density), static_cast<int>(w * density), CV_8U, cv::Scalar(128));
    if (i == 1) {
      tex.setTo(255);
      // Wall +x: u = y + 5, v = z. Texel x covers [x, x+1) / density metres.
      const cv::Point2d c(5.0 * density, 1.5 * density);
      const double r = side / 2 * density;
      cv::rectangle(tex, cv::Rect(cv::Point(static_cast<int>(c.x - r), static_cast<int>(c.y - r)),
                                  cv::Point(static_cast<int>(c.x + r), static_cast<int>(c.y + r))),
                    cv::Scalar(0), cv::FILLED);
    }
    s.textures.emplace_back(tex, density);
  }
  return s;
}

// Camera at `eye` looking along world +x (camera x = world -y, camera y = world -z), turned by
// small yaw and pitch angles.
Eigen::Isometry3d lookingEast(const Eigen::Vector3d& eye, double yaw, double pitch) {
  Eigen::Matrix3d R;
  R.col(0) = Eigen::Vector3d(0, -1, 0);
  R.col(1) = Eigen::Vector3d(0, 0, -1);
  R.col(2) = Eigen::Vector3d(1, 0, 0);
  R = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix() * R *
      Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitX()).toRotationMatrix();
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = R;
  T.translation() = eye;
  return T;
}

// Centroid of darkness (max - intensity) in a window around `guess`.
Eigen::Vector2d darkCentroid(const cv::Mat& img, const Eigen::Vector2d& guess, int radius) {
  double maxv = 0;
  cv::minMaxLoc(img, nullptr, &maxv);
  double sw = 0, su = 0, sv = 0;
  for (int v = static_cast<int>(guess.y()) - radius; v <= static_cast<int>(guess.y()) + radius; ++v)
    for (int u = static_cast<int>(guess.x()) - radius; u <= static_cast<int>(guess.x()) + radius; ++u) {
      const double w = maxv - img.at<float>(v, u);
      sw += w;
      su += w * u;
      sv += w * v;
    }
  return {su / sw, sv / sw};
}

class SquareProjection : public ::testing::TestWithParam<bool> {};

TEST_P(SquareProjection, RenderedSquareSitsAtTheAnalyticProjection) {
  const bool distorted = GetParam();
  const Scene scene = squareRoom(0.1);
  const Lens lens = Lens::standard(752, 480, distorted);
  const RayTable rays(lens);
  const camera::PinholeRadTan core_camera(lens.width, lens.height, lens.fx, lens.fy, lens.cx, lens.cy,
                                          {lens.k[0], lens.k[1], lens.k[2], lens.k[3]});
  const Eigen::Vector3d square(5, 0, 1.5);
  for (const auto& T : {lookingEast({1.0, 0.3, 1.4}, 0.1, 0.05), lookingEast({2.0, -0.8, 1.0}, -0.25, -0.2),
                        lookingEast({0.0, 1.5, 2.0}, -0.2, 0.1)}) {
    cv::Mat radiance;
    renderRadiance(scene, rays, T, radiance);
    Eigen::Vector2d expected;
    ASSERT_TRUE(core_camera.project(T.inverse() * square, expected));
    ASSERT_TRUE(core_camera.inImage(expected, 40));
    const Eigen::Vector2d measured = darkCentroid(radiance, expected, 30);
    EXPECT_LT((measured - expected).norm(), 0.25) << "expected " << expected.transpose() << " measured "
                                                  << measured.transpose();
  }
}

INSTANTIATE_TEST_SUITE_P(Lenses, SquareProjection, ::testing::Values(false, true));

TEST(Renderer, DepthIsTheDistanceAlongTheOpticalAxis) {
  const Scene scene = squareRoom(0.1);
  const RayTable rays(Lens::standard(160, 120, false));
  cv::Mat radiance, depth;
  // Looking straight at the +x wall from x = 1: every wall pixel is 4 m deep.
  renderRadiance(scene, rays, lookingEast({1.0, 0.0, 1.5}, 0.0, 0.0), radiance, &depth);
  EXPECT_NEAR(depth.at<float>(60, 80), 4.0f, 1e-5);
  EXPECT_NEAR(depth.at<float>(40, 30), 4.0f, 1e-5);
}

TEST(Texture, DistantFineDetailAveragesInsteadOfAliasing) {
  // A one-texel checkerboard seen from far away must come out as its mean grey, not a moire.
  cv::Mat checker(512, 512, CV_8U);
  for (int y = 0; y < 512; ++y)
    for (int x = 0; x < 512; ++x) checker.at<uchar>(y, x) = ((x + y) % 2) ? 255 : 0;
  const Texture t(checker, 256.0);
  for (double u = 0.3; u < 1.7; u += 0.137) {
    const float far = t.sample(u, 1.0, 0.05, 0.05, 1, 0);  // 12.8 texels per pixel
    EXPECT_NEAR(far, 127.5f, 4.0f) << u;
  }
  // At grazing incidence the anisotropic footprint averages along the stretched direction.
  EXPECT_NEAR(t.sample(1.0, 1.0, 0.004, 0.05, 0.6, 0.8), 127.5f, 12.0f);
}

}  // namespace
}  // namespace hiveslam::synth
