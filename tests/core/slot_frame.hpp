#pragma once
// A frame with `n` empty feature slots (zero keypoints, measurements and descriptors): enough
// for tests that build maps by hand, where only which slot observes which point matters.
#include "core/frame/frame.hpp"

namespace hiveslam::testing {

inline core::Frame slotFrame(size_t n) {
  core::Frame f;
  f.keypoints.resize(n);
  f.points.resize(n, Eigen::Vector2d::Zero());
  f.descriptors = cv::Mat::zeros(static_cast<int>(n), 32, CV_8U);
  return f;
}

}  // namespace hiveslam::testing
