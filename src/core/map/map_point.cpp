#include "core/map/map_point.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/features/hamming.hpp"
#include "core/map/keyframe.hpp"

namespace hiveslam::core {

void MapPoint::update(const std::vector<double>& scales) {
  if (observations.empty()) return;
  Eigen::Vector3d n = Eigen::Vector3d::Zero();
  std::vector<const uchar*> descs;
  KeyFrame* ref = observations.begin()->first;
  for (const auto& [kf, idx] : observations) {
    n += (position - kf->center()).normalized();
    descs.push_back(kf->frame.descriptors.ptr<uchar>(idx));
    if (kf->id < ref->id) ref = kf;
  }
  normal = n.normalized();
  // Distance range from the reference (first) observation's pyramid level.
  const int level = ref->frame.keypoints[static_cast<size_t>(observations.at(ref))].octave;
  const double dist = (position - ref->center()).norm();
  max_distance = dist * scales[static_cast<size_t>(level)];
  min_distance = max_distance / scales.back();
  // Descriptor: the one with the least median distance to the others.
  size_t best = 0;
  int best_median = std::numeric_limits<int>::max();
  for (size_t i = 0; i < descs.size(); ++i) {
    std::vector<int> d;
    for (size_t j = 0; j < descs.size(); ++j)
      if (i != j) d.push_back(features::hamming(descs[i], descs[j]));
    int median = 0;
    if (!d.empty()) {
      std::nth_element(d.begin(), d.begin() + d.size() / 2, d.end());
      median = d[d.size() / 2];
    }
    if (median < best_median) {
      best_median = median;
      best = i;
    }
  }
  descriptor = cv::Mat(1, 32, CV_8U);
  std::copy(descs[best], descs[best] + 32, descriptor.ptr<uchar>());
}

int MapPoint::predictLevel(double distance, const std::vector<double>& scales) const {
  const double ratio = max_distance / std::max(distance, 1e-9);
  const int level = static_cast<int>(std::ceil(std::log(ratio) / std::log(scales.size() > 1 ? scales[1] : 1.2)));
  return std::clamp(level, 0, static_cast<int>(scales.size()) - 1);
}

}  // namespace hiveslam::core
