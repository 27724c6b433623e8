#pragma once
// How much an image repeats itself: the share of its ORB features (OpenCV's, up to 1000) that
// have a look-alike elsewhere in the same image, a descriptor within Hamming distance 50 (the
// distance a match must pass in ORB-SLAM's searches) on a keypoint more than 16 pixels away
// (nearer is the same corner at another pyramid level). Repeated patterns (chessboards, logos,
// text, slats) are what wrong matches along an epipolar line are made of. Real footage measures
// 0.02-0.06 at the median frame (KITTI 06 and 07, phone_room_droidcam) and 0.35 at phone_room's
// 90th percentile (a keyboard filling the view); a calibration chessboard photo 0.8-1.
// Header-only: both the renderer (which stands alone) and eval's image statistics use it.
#include <opencv2/core.hpp>
#include <opencv2/core/hal/hal.hpp>
#include <opencv2/features2d.hpp>
#include <vector>

namespace hiveslam {

inline double lookAlikeShare(const cv::Mat& gray) {
  static thread_local const cv::Ptr<cv::ORB> orb = cv::ORB::create(1000);
  std::vector<cv::KeyPoint> keypoints;
  cv::Mat descriptors;
  orb->detectAndCompute(gray, cv::noArray(), keypoints, descriptors);
  if (keypoints.size() < 2) return 0;
  size_t with = 0;
  for (int i = 0; i < descriptors.rows; ++i)
    for (int j = 0; j < descriptors.rows; ++j) {
      const cv::Point2f d = keypoints[static_cast<size_t>(i)].pt - keypoints[static_cast<size_t>(j)].pt;
      if (i == j || d.dot(d) <= 16.f * 16.f) continue;
      if (cv::hal::normHamming(descriptors.ptr<uchar>(i), descriptors.ptr<uchar>(j), descriptors.cols) <= 50) {
        ++with;
        break;
      }
    }
  return static_cast<double>(with) / static_cast<double>(keypoints.size());
}

}  // namespace hiveslam
