#pragma once
// A 3D landmark: position, the keyframes that observe it (keypoint index in each), a
// representative descriptor, and the viewing direction and distance range over which it can be
// matched. Guarded by its map's mutex (see map.hpp).
#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "core/map/flat_map_by_id.hpp"
#include "core/map/ids.hpp"

namespace hiveslam::core {

class KeyFrame;

class MapPoint {
 public:
  MapPoint(Id id, const Eigen::Vector3d& position, Id first_keyframe) : id(id), position(position), first_keyframe(first_keyframe) {}

  const Id id;
  Eigen::Vector3d position;
  const Id first_keyframe;
  FlatMapById<KeyFrame, int> observations;  // keyframe -> keypoint index, by keyframe id
  cv::Mat descriptor;                     // 1x32, the observation descriptor closest to the others
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();  // mean viewing direction
  double min_distance = 0, max_distance = 0;         // scale-invariance range
  int visible = 1, found = 1;  // times predicted in view / actually matched, for culling
  bool bad = false;

  double foundRatio() const { return static_cast<double>(found) / visible; }
  // Recomputes descriptor, normal and distance range from the observations.
  void update(const std::vector<double>& level_scales);
  // Pyramid level at which a keypoint of this point should appear from `distance`.
  int predictLevel(double distance, const std::vector<double>& level_scales) const;
};

}  // namespace hiveslam::core
