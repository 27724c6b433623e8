#pragma once
// How distinct each keypoint is within its own image, and how much an image repeats itself.
//
// A keypoint's look-alike is the most similar other keypoint of the same image more than 16
// pixels away (nearer is the same corner at another pyramid level). A keypoint on
// smooth shading or in a repeated pattern (chessboards, logos, text, slats) has one a few bits
// away, and a match across two images no better than that twin could as well have been the
// twin: that is what wrong matches along an epipolar line are made of.
//
// Header-only in common: local mapping's triangulation check, eval's match diagnostics, the
// renderer's photo filter and eval's image statistics all measure the same thing.
#include <opencv2/core.hpp>
#include <opencv2/features2d.hpp>
#include <algorithm>
#include <cstdint>
#include <vector>

#include "common/hamming.hpp"

namespace hiveslam {

// Per keypoint, the Hamming distance to its nearest look-alike more than 16 px away (255: none).
// Only the keypoints `asked_for` are measured (the others read 255): the core asks only for the
// corners its detector found at its lower threshold.
inline std::vector<uint8_t> lookAlikeDistances(const std::vector<cv::KeyPoint>& keypoints, const cv::Mat& descriptors,
                                               bool (*asked_for)(const cv::KeyPoint&) = nullptr) {
  const size_t n = keypoints.size();
  std::vector<uint8_t> nearest(n, 255);
  std::vector<char> asked(n);
  for (size_t a = 0; a < n; ++a) asked[a] = !asked_for || asked_for(keypoints[a]);
  constexpr float min2 = 16.f * 16.f;
  for (size_t a = 0; a < n; ++a) {
    const unsigned char* da = descriptors.ptr<uchar>(static_cast<int>(a));
    for (size_t b = a + 1; b < n; ++b) {
      if (!asked[a] && !asked[b]) continue;
      const cv::Point2f d = keypoints[a].pt - keypoints[b].pt;
      if (d.dot(d) <= min2) continue;
      const auto h = static_cast<uint8_t>(std::min(255, hamming(da, descriptors.ptr<uchar>(static_cast<int>(b)))));
      if (asked[a]) nearest[a] = std::min(nearest[a], h);
      if (asked[b]) nearest[b] = std::min(nearest[b], h);
    }
  }
  return nearest;
}

// The share of an image's ORB features (OpenCV's, up to 1000) with a look-alike within Hamming
// distance 50, the distance a match must pass in ORB-SLAM's searches. Real footage measures
// 0.02-0.06 at the median frame (KITTI 06 and 07, phone_room_droidcam) and 0.35 at phone_room's
// 90th percentile (a keyboard filling the view); a calibration chessboard photo 0.8-1.
inline double lookAlikeShare(const cv::Mat& gray) {
  static thread_local const cv::Ptr<cv::ORB> orb = cv::ORB::create(1000);
  std::vector<cv::KeyPoint> keypoints;
  cv::Mat descriptors;
  orb->detectAndCompute(gray, cv::noArray(), keypoints, descriptors);
  if (keypoints.size() < 2) return 0;
  const auto nearest = lookAlikeDistances(keypoints, descriptors);
  const auto with = std::count_if(nearest.begin(), nearest.end(), [](uint8_t d) { return d <= 50; });
  return static_cast<double>(with) / static_cast<double>(keypoints.size());
}

}  // namespace hiveslam
