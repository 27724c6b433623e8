#pragma once
// The SLAM system of one node: tracking and local mapping behind one call per frame. This is
// the sequential (lockstep) composition: each frame is tracked, then its keyframe, if any, is
// mapped before the next frame, so the same input always gives the same trajectory.
#include <memory>
#include <vector>

#include "core/camera/camera_model.hpp"
#include "core/mapping/local_mapper.hpp"
#include "core/tracking/tracker.hpp"

namespace hiveslam::core {

struct FrameRecord {
  size_t index = 0;
  double timestamp = 0;
  bool tracked = false;
  std::shared_ptr<KeyFrame> reference;
  Eigen::Isometry3d T_c_ref = Eigen::Isometry3d::Identity();  // pose relative to the reference
  Id map = kNoId;
  double tracking_ms = 0;
};

class SlamSystem {
 public:
  SlamSystem(const SlamSettings& settings, std::shared_ptr<const camera::CameraModel> camera, uint16_t node = 0);

  // Tracks one grey image (and maps its keyframe); returns the frame's record.
  const FrameRecord& process(const cv::Mat& gray, double timestamp);

  const std::vector<FrameRecord>& frames() const { return records_; }
  const std::vector<std::shared_ptr<Map>>& maps() const { return maps_; }
  int failures() const { return tracker_.failures(); }
  const MappingStats& mappingStats() const { return mapper_.stats(); }
  // Current camera-to-world pose of a tracked frame (through its reference keyframe, so later
  // optimizations of the keyframes move it too).
  Eigen::Isometry3d poseOf(const FrameRecord& r) const;
  // The map holding the most keyframes (the one trajectories are reported in).
  std::shared_ptr<Map> largestMap() const;

 private:
  SlamSettings settings_;
  std::shared_ptr<const camera::CameraModel> camera_;
  IdGenerator ids_;
  features::OrbExtractor extractor_;
  Tracker tracker_;
  LocalMapper mapper_;
  std::vector<std::shared_ptr<Map>> maps_;
  std::vector<FrameRecord> records_;
};

}  // namespace hiveslam::core
