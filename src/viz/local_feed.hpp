#pragma once
// Feeds a LiveView from this process's SLAM system: every frame from the tracking thread (a
// short copy: pose, keypoints, a reference to the image), and on its own thread a copy of the
// maps when they changed (at most ViewSettings::cloud_hz) and the panel's values (status_hz).
#include <nlohmann/json.hpp>

#include <atomic>
#include <functional>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "core/system/slam_system.hpp"
#include "viz/live_view.hpp"
#include "viz/view_settings.hpp"

namespace hiveslam::viz {

class LocalFeed {
 public:
  // `node_report`: a distributed node's report (DistributedNode::report), read for the panel's
  // peers, tasks and traffic; empty for a standalone run. Installs the frame listener on `slam`
  // (before its first frame).
  // `wants_scene`: whether anyone reads the maps now (a page open, a ROS reader of the points);
  // the maps are copied only then (empty: always).
  LocalFeed(LiveView& view, std::string node, core::SlamSystem& slam, ViewSettings settings,
            std::function<nlohmann::json()> node_report = {}, std::function<bool()> wants_scene = {});
  ~LocalFeed();
  LocalFeed(const LocalFeed&) = delete;
  LocalFeed& operator=(const LocalFeed&) = delete;
  // Stops the thread after one last map copy and panel (the end of a run).
  void stop();

 private:
  void onFrame(const core::FrameRecord& r, const Eigen::Isometry3d& T_cw, const std::vector<cv::KeyPoint>& keypoints,
               const cv::Mat& gray);
  void run();
  void refreshScene(bool force);
  void refreshPanel(double seconds);
  LiveView& view_;
  const std::string node_;
  core::SlamSystem& slam_;
  ViewSettings settings_;
  std::function<nlohmann::json()> node_report_;
  std::function<bool()> wants_scene_;
  // Tracking's counts for the panel (written on the tracking thread).
  std::mutex counts_mutex_;
  int frames_ = 0, tracked_ = 0, keyframes_made_ = 0;
  std::vector<double> recent_tracking_ms_;
  // For rates between two panels (feed thread only).
  double last_cpu_ = 0, last_seconds_ = 0;
  uint64_t last_bytes_in_ = 0, last_bytes_out_ = 0, last_kf_msgs_ = 0, last_map_msgs_ = 0;
  uint64_t scene_fingerprint_ = 0;
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

// Seconds of CPU this process has used.
double processCpuSeconds();

}  // namespace hiveslam::viz
