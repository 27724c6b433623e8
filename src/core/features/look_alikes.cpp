#include "core/features/look_alikes.hpp"

#include <algorithm>

#include "core/features/hamming.hpp"

namespace hiveslam::features {

std::vector<uint8_t> lookAlikeDistances(const std::vector<cv::KeyPoint>& keypoints, const cv::Mat& descriptors,
                                        float min_separation_px) {
  const size_t n = keypoints.size();
  std::vector<uint8_t> nearest(n, 255);
  const float min2 = min_separation_px * min_separation_px;
  for (size_t a = 0; a < n; ++a) {
    const unsigned char* da = descriptors.ptr<uchar>(static_cast<int>(a));
    for (size_t b = a + 1; b < n; ++b) {
      const cv::Point2f d = keypoints[a].pt - keypoints[b].pt;
      if (d.dot(d) <= min2) continue;
      const auto h = static_cast<uint8_t>(std::min(255, hamming(da, descriptors.ptr<uchar>(static_cast<int>(b)))));
      nearest[a] = std::min(nearest[a], h);
      nearest[b] = std::min(nearest[b], h);
    }
  }
  return nearest;
}

}  // namespace hiveslam::features
