#include "viz/ros/ros_viz_reader.hpp"

#include <fmt/format.h>

#include "common/thread_name.hpp"
#include "communication/dds/checked_type.hpp"
#include "communication/dds/node_announcement.hpp"
#include "communication/dds/topic_discovery.hpp"
#include "geometry_msgs/msg/PoseStampedPubSubTypes.h"
#include "hiveslam_msgs/msg/NodeInfoPubSubTypes.h"
#include "nav_msgs/msg/PathPubSubTypes.h"
#include "sensor_msgs/msg/PointCloud2PubSubTypes.h"
#include "std_msgs/msg/StringPubSubTypes.h"
#include "visualization_msgs/msg/MarkerArrayPubSubTypes.h"
#include "viz/ros/ros_messages.hpp"
#include "viz/ros/viz_participant.hpp"

namespace hiveslam::viz::ros {

namespace dds = eprosima::fastdds::dds;

namespace {

constexpr const char* kNodesTopic = "rt/hiveslam/nodes";  // the nodes' announcements (dds_transport.cpp)
const char* const kTaskNames[] = {"tr", "lm", "lc"};

std::string hostedTasks(uint8_t hosted) {
  std::string s;
  for (int i = 0; i < 3; ++i)
    if (hosted & (1 << i)) s += (s.empty() ? "" : ",") + std::string(kTaskNames[i]);
  return s.empty() ? "none" : s;
}

}  // namespace

struct RosVizReader::Impl {
  communication::TopicDiscovery discovery;
  VizParticipant participant;
  std::mutex mutex;
  std::set<std::string> followed;
  struct Scene {
    MapScene points;
    SceneLines lines;
  };
  std::map<std::string, Scene> scenes;  // per node: the last points and lines, joined
  std::map<uint16_t, std::string> announced;  // node id -> name, from the announcements
  Impl(int domain) : discovery(domain), participant(domain, "hiveslam-view") {}
};

RosVizReader::RosVizReader(LiveView& view, int domain) : impl_(std::make_unique<Impl>(domain)), view_(view) {
  impl_->participant.reader(kNodesTopic, dds::TypeSupport(new communication::CheckedType<hiveslam_msgs::msg::NodeInfoPubSubType, communication::noteDroppedAnnouncement>()), 16,
                            [this](dds::DataReader* r) {
                              takeAll<hiveslam_msgs::msg::NodeInfo>(r, [this](hiveslam_msgs::msg::NodeInfo& m) {
                                std::string why;
                                if (!communication::fromIdl(m, why)) {
                                  communication::noteDroppedAnnouncement();
                                  return;
                                }
                                ++received_;
                                std::string text;
                                {
                                  std::lock_guard lock(impl_->mutex);
                                  const bool known = impl_->announced.count(m.node()) > 0;
                                  if (m.leaving()) {
                                    impl_->announced.erase(m.node());
                                    text = "left";
                                  } else if (!known) {
                                    impl_->announced[m.node()] = m.name();
                                    text = "announced, running " + hostedTasks(m.hosted());
                                  }
                                }
                                if (!text.empty()) view_.addEvent(m.name(), fmt::format("node {} {}", m.node(), text));
                              });
                            });
  thread_ = std::thread([this] { run(); });
}

RosVizReader::~RosVizReader() {
  stop_ = true;
  if (thread_.joinable()) thread_.join();
  impl_->participant.close();
}

void RosVizReader::run() {
  nameThisThread("viz-view");
  const std::string prefix = "rt/hiveslam/";
  while (!stop_) {
    for (const auto& t : impl_->discovery.topics()) {
      if (t.name.rfind(prefix, 0) != 0 || t.writers == 0) continue;
      const std::string rest = t.name.substr(prefix.size());
      const auto slash = rest.find('/');
      if (slash == std::string::npos || rest.substr(slash + 1) != "status") continue;
      follow(rest.substr(0, slash));
    }
    for (int i = 0; i < 5 && !stop_; ++i) std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
}

void RosVizReader::follow(const std::string& node) {
  {
    std::lock_guard lock(impl_->mutex);
    if (!impl_->followed.insert(node).second) return;
  }
  auto& p = impl_->participant;
  p.reader(vizTopic(node, "status"), dds::TypeSupport(new communication::CheckedType<std_msgs::msg::StringPubSubType>()), 1, [this, node](dds::DataReader* r) {
    takeAll<std_msgs::msg::String>(r, [&](std_msgs::msg::String& m) {
      auto panel = nlohmann::json::parse(m.data(), nullptr, false);
      if (panel.is_discarded() || !panel.is_object()) {
        ++dropped_;
        return;
      }
      ++received_;
      view_.setPanel(node, std::move(panel));
    });
  });
  p.reader(vizTopic(node, "pose"), dds::TypeSupport(new communication::CheckedType<geometry_msgs::msg::PoseStampedPubSubType>()), 1,
           [this, node](dds::DataReader* r) {
             takeAll<geometry_msgs::msg::PoseStamped>(r, [&](geometry_msgs::msg::PoseStamped& m) {
               ++received_;
               const PathPose pose = fromPoseStamped(m);
               LiveFrame f;
               f.timestamp = pose.timestamp;
               f.tracked = true;
               f.T_wc = pose.T_wc;
               view_.setFrame(node, std::move(f), false);
             });
           });
  p.reader(vizTopic(node, "path"), dds::TypeSupport(new communication::CheckedType<nav_msgs::msg::PathPubSubType>()), 1, [this, node](dds::DataReader* r) {
    takeAll<nav_msgs::msg::Path>(r, [&](nav_msgs::msg::Path& m) {
      ++received_;
      view_.setPath(node, fromPath(m));
    });
  });
  auto publish_scene = [this, node] {
    auto scene = std::make_shared<MapScene>();
    {
      std::lock_guard lock(impl_->mutex);
      const auto& s = impl_->scenes[node];
      scene->points = s.points.points;
      scene->lines = s.lines;
    }
    view_.setScene(node, std::move(scene));
  };
  p.reader(vizTopic(node, "points"), dds::TypeSupport(new communication::CheckedType<sensor_msgs::msg::PointCloud2PubSubType>()), 1,
           [this, node, publish_scene](dds::DataReader* r) {
             takeAll<sensor_msgs::msg::PointCloud2>(r, [&](sensor_msgs::msg::PointCloud2& m) {
               MapScene s = fromPointCloud(m);
               if (s.points.empty() && m.width() * m.height() > 0) {
                 ++dropped_;
                 return;
               }
               ++received_;
               {
                 std::lock_guard lock(impl_->mutex);
                 impl_->scenes[node].points = std::move(s);
               }
               publish_scene();
             });
           });
  p.reader(vizTopic(node, "keyframe_markers"), dds::TypeSupport(new communication::CheckedType<visualization_msgs::msg::MarkerArrayPubSubType>()), 1,
           [this, node, publish_scene](dds::DataReader* r) {
             takeAll<visualization_msgs::msg::MarkerArray>(r, [&](visualization_msgs::msg::MarkerArray& m) {
               ++received_;
               {
                 std::lock_guard lock(impl_->mutex);
                 impl_->scenes[node].lines = fromMarkers(m);
               }
               publish_scene();
             });
           });
}

}  // namespace hiveslam::viz::ros
