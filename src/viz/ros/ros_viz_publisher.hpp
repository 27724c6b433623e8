#pragma once
// Publishes one node's part of a LiveView as ROS 2 topics under /hiveslam/<node>/: pose
// (geometry_msgs/PoseStamped), tf (tf2_msgs/TFMessage), path (nav_msgs/Path), points
// (sensor_msgs/PointCloud2), keyframe_markers (visualization_msgs/MarkerArray; "keyframes" is
// the node's own keyframe topic, of another type) and status
// (std_msgs/String, the panel's values as JSON), each at most at its ViewSettings rate and
// only while some reader listens. Its own thread; the node's threads only write the LiveView.
#include <atomic>
#include <chrono>
#include <functional>
#include <memory>
#include <string>
#include <thread>

#include "viz/live_view.hpp"
#include "viz/view_settings.hpp"

namespace hiveslam::viz::ros {

class RosVizPublisher {
 public:
  // `publishes_map`: whether this node holds the newest map now (it hosts local mapping); the
  // points and keyframes come from that node only.
  RosVizPublisher(const LiveView& view, int domain, std::string node, ViewSettings settings,
                  std::function<bool()> publishes_map);
  ~RosVizPublisher();
  RosVizPublisher(const RosVizPublisher&) = delete;
  RosVizPublisher& operator=(const RosVizPublisher&) = delete;
  // Messages written so far (all topics).
  uint64_t written() const { return written_; }
  // Whether this node's maps go out now: it makes the map, and a reader listens to its points
  // or keyframes (or their writers are still to be made).
  bool wantsMap() const { return publishes_map_ && publishes_map_() && map_readers_; }

 private:
  // What was sent, and when each topic is next due.
  struct State {
    uint64_t seen = 0;
    std::chrono::steady_clock::time_point next_pose{}, next_path{}, next_cloud{}, next_status{};
    uint64_t pose_version = 0, scene_version = 0, panel_version = 0;
    size_t path_size = 0;
    double stamp = 0;  // of the newest frame: the point cloud's and markers' stamp
  };
  void run();
  // One pass over the view: each topic that changed and is due (any that changed: force).
  void publishOnce(State& state, bool force);
  struct Writers;
  const LiveView& view_;
  std::string node_;
  ViewSettings settings_;
  std::function<bool()> publishes_map_;
  std::unique_ptr<Writers> writers_;
  std::atomic<bool> stop_{false};
  std::atomic<uint64_t> written_{0};
  std::atomic<bool> map_readers_{true};
  std::thread thread_;
};

}  // namespace hiveslam::viz::ros
