#pragma once
// What the live view shows of one tracked frame: the camera, its image and its features. Made
// on the tracking thread at the cost of a few copies (the image is shared, not copied: every
// frame source hands out a new cv::Mat per frame).
#include <Eigen/Geometry>
#include <opencv2/core.hpp>

#include <cstdint>
#include <vector>

namespace hiveslam::viz {

struct LiveFrame {
  size_t index = 0;
  double timestamp = 0;
  bool tracked = false;
  int inliers = 0;
  uint64_t map = 0;  // the map the pose is in (core::Id)
  double tracking_ms = 0;
  Eigen::Isometry3d T_wc = Eigen::Isometry3d::Identity();  // when tracked
  cv::Mat image;                                           // grey, as tracked
  std::vector<cv::Point2f> features;  // every keypoint, on the image as given
  std::vector<cv::Point2f> matched;   // those matched to map points (undistorted pixels)
};

// One tracked camera position of the trajectory as the view draws it.
struct PathPose {
  double timestamp = 0;
  uint64_t map = 0;
  Eigen::Isometry3d T_wc = Eigen::Isometry3d::Identity();
};

}  // namespace hiveslam::viz
