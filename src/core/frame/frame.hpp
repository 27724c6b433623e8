#pragma once
// One image turned into what the SLAM core works with: ORB keypoints, their undistorted
// coordinates on the ideal pinhole image of the camera (fx fy cx cy, no distortion), descriptors
// and a grid for radius queries.
#include <Eigen/Core>
#include <opencv2/core.hpp>
#include <vector>

#include "core/camera/camera_model.hpp"
#include "core/features/orb_extractor.hpp"
#include "core/frame/feature_grid.hpp"

namespace hiveslam::core {

// The linear part of the camera: BA and tracking work on undistorted coordinates with it.
struct Intrinsics {
  double fx = 1, fy = 1, cx = 0, cy = 0;
  Eigen::Vector2d project(const Eigen::Vector3d& p_c) const {
    return {fx * p_c.x() / p_c.z() + cx, fy * p_c.y() / p_c.z() + cy};
  }
  Eigen::Vector3d ray(const Eigen::Vector2d& uv) const { return {(uv.x() - cx) / fx, (uv.y() - cy) / fy, 1.0}; }
};

struct Frame {
  size_t index = 0;
  double timestamp = 0.0;
  std::vector<cv::KeyPoint> keypoints;   // as detected (distorted image)
  std::vector<Eigen::Vector2d> points;   // undistorted, on the ideal pinhole image
  cv::Mat descriptors;                   // one 32-byte row per keypoint
  FeatureGrid grid;
  Intrinsics K;
  int width = 0, height = 0;

  bool inImage(const Eigen::Vector2d& uv) const { return uv.x() >= 0 && uv.y() >= 0 && uv.x() < width && uv.y() < height; }

  size_t size() const { return keypoints.size(); }
  // Builds the grid over `points` (after extraction, or after loading a saved keyframe).
  void buildGrid();
  static constexpr double kFarOutside = -1e6;  // where a keypoint with no pinhole image goes
  // f(i) for each keypoint i whose undistorted point lies within r pixels of (x, y).
  template <class F>
  void forEachInRadius(double x, double y, double r, F&& f) const {
    grid.forEachInRadius(points, x, y, r, std::forward<F>(f));
  }
};

// Extracts and undistorts the features of one grey image.
Frame makeFrame(const cv::Mat& gray, size_t index, double timestamp, const features::OrbExtractor& extractor,
                const camera::CameraModel& camera);

}  // namespace hiveslam::core
