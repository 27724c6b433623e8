#pragma once
// How distinct each keypoint is within its own image: the Hamming distance from its descriptor
// to the nearest descriptor of another keypoint more than `min_separation_px` away (nearer is
// the same corner at another pyramid level). A keypoint on smooth shading or in a repeated
// pattern has a twin a few bits away somewhere in its image; a pair of keypoints matched across
// two images no closer than that twin could as well have been the twin.
#include <opencv2/core.hpp>
#include <cstdint>
#include <vector>

namespace hiveslam::features {

std::vector<uint8_t> lookAlikeDistances(const std::vector<cv::KeyPoint>& keypoints, const cv::Mat& descriptors,
                                        float min_separation_px = 16.f);

}  // namespace hiveslam::features
