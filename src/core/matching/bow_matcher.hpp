#pragma once
// Matching by bag of words: features of two images are compared only when the vocabulary puts
// them under the same node, so a keyframe pair is matched without a pose prior in a fraction
// of the brute-force cost (loop and merge verification, relocalization).
#include <functional>
#include <utility>
#include <vector>

#include "core/map/keyframe.hpp"

namespace hiveslam::core {

// Pairs (index in a, index in b) of keypoints that both carry a map point (not bad), nearest
// neighbour under kMatchLow and clearly better than the second (ratio), consistent with the
// dominant rotation between the images. The caller holds the mutex of each keyframe's map.
std::vector<std::pair<int, int>> matchKeyframesByBow(const KeyFrame& a, const KeyFrame& b, double ratio = 0.75);

// Pairs of keypoints whose slots hold no map point, under the same node, nearest under kMatchLow
// among the candidates `compatible(i, j)` admits (new points: the epipolar band), clearly better
// than the second and consistent with the dominant rotation. Needs both feature vectors.
std::vector<std::pair<int, int>> matchUnmappedByBow(const KeyFrame& a, const KeyFrame& b,
                                                    const std::function<bool(int, int)>& compatible,
                                                    double ratio = 0.7);

// Same for a frame (its keypoints free to match) against a keyframe's map points: slot i of the
// result holds the keyframe keypoint matched to frame keypoint i, or -1.
std::vector<int> matchFrameByBow(const Frame& frame, const place::FeatureVector& frame_features, const KeyFrame& kf,
                                 double ratio = 0.75);

}  // namespace hiveslam::core
