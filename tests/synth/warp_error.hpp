#pragma once
// How well two views of a rendered scene agree with a pose and a camera: image a, whose
// per-pixel depth is known, warped into image b; the mean absolute grey-level difference over the
// pixels that land inside b. The true pose and lens make it small; a wrong one does not.
#include <gtest/gtest.h>

#include <cmath>
#include <opencv2/imgproc.hpp>

#include "core/camera/camera_model.hpp"

namespace hiveslam::synth {

template <typename PixelA>
double warpError(const cv::Mat& a, const cv::Mat& depth_a, const cv::Mat& b, const Eigen::Isometry3d& T_ba,
                 const camera::CameraModel& cam) {
  double sum = 0;
  int n = 0;
  for (int v = 5; v < a.rows - 5; ++v)
    for (int u = 5; u < a.cols - 5; ++u) {
      const Eigen::Vector3d bearing = cam.unproject(Eigen::Vector2d(u, v));
      const Eigen::Vector3d p_a = bearing * depth_a.at<float>(v, u) / bearing.z();
      Eigen::Vector2d uv;
      if (!cam.project(T_ba * p_a, uv) || !cam.inImage(uv, 2)) continue;
      cv::Mat patch;
      cv::getRectSubPix(b, {1, 1}, cv::Point2f(static_cast<float>(uv.x()), static_cast<float>(uv.y())), patch, CV_32F);
      sum += std::abs(patch.at<float>(0, 0) - a.at<PixelA>(v, u));
      ++n;
    }
  EXPECT_GT(n, 1000);
  return sum / std::max(n, 1);
}

}  // namespace hiveslam::synth
