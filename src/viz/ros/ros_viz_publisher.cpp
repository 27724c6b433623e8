#include "viz/ros/ros_viz_publisher.hpp"

#include <fmt/format.h>

#include "common/thread_name.hpp"
#include "geometry_msgs/msg/PoseStampedPubSubTypes.h"
#include "nav_msgs/msg/PathPubSubTypes.h"
#include "sensor_msgs/msg/PointCloud2PubSubTypes.h"
#include "std_msgs/msg/StringPubSubTypes.h"
#include "tf2_msgs/msg/TFMessagePubSubTypes.h"
#include "visualization_msgs/msg/MarkerArrayPubSubTypes.h"
#include "viz/ros/ros_messages.hpp"
#include "viz/ros/viz_participant.hpp"

namespace hiveslam::viz::ros {

namespace dds = eprosima::fastdds::dds;

// Each writer is made when its first message is due: a topic appears only on the nodes that
// have something for it (pose and path on TR, points and keyframes where the map is made).
struct RosVizPublisher::Writers {
  VizParticipant participant;
  const std::string node;
  dds::DataWriter *pose = nullptr, *tf = nullptr, *path = nullptr, *points = nullptr, *keyframes = nullptr,
                  *status = nullptr;
  Writers(int domain, const std::string& node_name) : participant(domain, fmt::format("hiveslam-viz-{}", node_name)), node(node_name) {}
  template <class PubSubType>
  dds::DataWriter* get(dds::DataWriter*& w, const char* what, int depth) {
    if (!w) w = participant.writer(vizTopic(node, what), dds::TypeSupport(new PubSubType()), depth);
    return w;
  }
  dds::DataWriter* posesWriter() { return get<geometry_msgs::msg::PoseStampedPubSubType>(pose, "pose", 1); }
  dds::DataWriter* tfWriter() { return get<tf2_msgs::msg::TFMessagePubSubType>(tf, "tf", 10); }
  dds::DataWriter* pathWriter() { return get<nav_msgs::msg::PathPubSubType>(path, "path", 1); }
  dds::DataWriter* pointsWriter() { return get<sensor_msgs::msg::PointCloud2PubSubType>(points, "points", 1); }
  dds::DataWriter* markersWriter() {
    return get<visualization_msgs::msg::MarkerArrayPubSubType>(keyframes, "keyframe_markers", 1);
  }
  dds::DataWriter* statusWriter() { return get<std_msgs::msg::StringPubSubType>(status, "status", 1); }
};

RosVizPublisher::RosVizPublisher(const LiveView& view, int domain, std::string node, ViewSettings settings,
                                 std::function<bool()> publishes_map)
    : view_(view),
      node_(std::move(node)),
      settings_(settings),
      publishes_map_(std::move(publishes_map)),
      writers_(std::make_unique<Writers>(domain, node_)) {
  thread_ = std::thread([this] { run(); });
}

RosVizPublisher::~RosVizPublisher() {
  stop_ = true;
  if (thread_.joinable()) thread_.join();
  writers_.reset();
}

void RosVizPublisher::run() {
  nameThisThread("viz-ros");
  State state;
  while (!stop_) {
    view_.waitForChange(state.seen, std::chrono::milliseconds(100));
    publishOnce(state, false);
  }
  // The run is over: the last pose, path, maps and panel go out whatever the rates, and each
  // writer waits (bounded) until its readers have them.
  publishOnce(state, true);
  for (auto* w : {writers_->pose, writers_->tf, writers_->path, writers_->points, writers_->keyframes, writers_->status})
    if (w) w->wait_for_acknowledgments(eprosima::fastrtps::Duration_t(1, 0));
}

void RosVizPublisher::publishOnce(State& st, bool force) {
  map_readers_ = !writers_->points || !writers_->keyframes || hasReaders(writers_->points) || hasReaders(writers_->keyframes);
  using Clock = std::chrono::steady_clock;
  auto period = [](double hz) { return std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(1.0 / std::max(hz, 1e-3))); };
  auto& next_pose = st.next_pose;
  auto& next_path = st.next_path;
  auto& next_cloud = st.next_cloud;
  auto& next_status = st.next_status;
  auto& pose_version = st.pose_version;
  auto& scene_version = st.scene_version;
  auto& panel_version = st.panel_version;
  auto& path_size = st.path_size;
  auto& stamp = st.stamp;
  {
    st.seen = view_.version();
    const auto now = Clock::now();
    // Copies under the view's lock; messages are built after it.
    std::optional<PathPose> pose;
    std::vector<PathPose> path;
    std::shared_ptr<const MapScene> scene;
    std::optional<nlohmann::json> panel;
    // The path is copied only for a listening reader: it grows with every tracked frame, and
    // the copy is made under the view's lock, which the tracking thread takes once a frame.
    const bool path_wanted = (force || now >= next_path) && writers_->path && hasReaders(writers_->path);
    const bool pose_due = force || now >= next_pose,
               cloud_due = force || now >= next_cloud, status_due = force || now >= next_status;
    view_.read([&](const std::map<std::string, NodeState>& nodes) {
      const auto it = nodes.find(node_);
      if (it == nodes.end()) return;
      const NodeState& n = it->second;
      if (n.frame) stamp = n.frame->timestamp;
      if (pose_due && n.frame && n.frame->tracked && n.frame_version != pose_version) {
        pose = PathPose{n.frame->timestamp, n.frame->map, n.frame->T_wc};
        pose_version = n.frame_version;
      }
      if (path_wanted && n.path.size() != path_size) {
        path = n.path;
        path_size = n.path.size();
      }
      if (cloud_due && n.scene && n.scene_version != scene_version) {
        scene = n.scene;
        scene_version = n.scene_version;
      }
      if (status_due && n.panel_version != panel_version) {
        panel = n.panel;
        panel_version = n.panel_version;
      }
    });
    if (pose) {
      next_pose = now + period(settings_.pose_hz);
      writers_->pathWriter();  // the path's topic appears with the first pose
      if (hasReaders(writers_->posesWriter())) {
        auto m = toPoseStamped(*pose);
        writers_->posesWriter()->write(&m);
        ++written_;
      }
      if (hasReaders(writers_->tfWriter())) {
        auto m = toTf(*pose);
        writers_->tf->write(&m);
        ++written_;
      }
    }
    if (!path.empty()) {
      next_path = now + period(settings_.path_hz);
      auto m = toPath(path, path.back().timestamp);
      writers_->path->write(&m);
      ++written_;
    }
    if (scene) {
      next_cloud = now + period(settings_.cloud_hz);
      if (publishes_map_ && publishes_map_()) {
        if (hasReaders(writers_->pointsWriter())) {
          auto m = toPointCloud(*scene, stamp);
          writers_->points->write(&m);
          ++written_;
        }
        if (hasReaders(writers_->markersWriter())) {
          auto m = toMarkers(*scene, stamp);
          writers_->keyframes->write(&m);
          ++written_;
        }
      }
    }
    if (panel) {
      next_status = now + period(settings_.status_hz);
      if (hasReaders(writers_->statusWriter())) {
        std_msgs::msg::String m;
        m.data(panel->dump());
        writers_->status->write(&m);
        ++written_;
      }
    }
  }
}

}  // namespace hiveslam::viz::ros
