#pragma once
// The topics and types on a DDS domain, as discovery reports them: what `hiveslam topics`
// lists (like `ros2 topic list -t`, without ROS 2) and how `hiveslam view` finds the nodes of a
// running cluster. Its participant has no reader or writer of its own.
#include <memory>
#include <string>
#include <vector>

namespace hiveslam::communication {

struct DiscoveredTopic {
  std::string name, type;  // as on the wire: "rt/hiveslam/tr/pose", "geometry_msgs::msg::dds_::PoseStamped_"
  int writers = 0, readers = 0;  // present now
};

class TopicDiscovery {
 public:
  explicit TopicDiscovery(int domain);
  ~TopicDiscovery();
  TopicDiscovery(const TopicDiscovery&) = delete;
  TopicDiscovery& operator=(const TopicDiscovery&) = delete;
  // Sorted by name, then type; topics whose endpoints all left are kept with zero counts.
  std::vector<DiscoveredTopic> topics() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// "rt/hiveslam/tr/pose" -> "/hiveslam/tr/pose"; "" for a name ROS 2 does not map ("rq/..." and
// "rr/..." are services, anything else is not ROS).
std::string rosTopicName(const std::string& dds_name);
// "geometry_msgs::msg::dds_::PoseStamped_" -> "geometry_msgs/msg/PoseStamped"; other names as
// they are.
std::string rosTypeName(const std::string& dds_type);

}  // namespace hiveslam::communication
