#pragma once
// The live view as ROS 2 standard messages (RViz2, Foxglove and `ros2 topic echo` read them
// with no hiveslam code): the camera as geometry_msgs/PoseStamped and a map -> camera TF, the
// trajectory as nav_msgs/Path, the map points as sensor_msgs/PointCloud2 (x, y, z and the
// point's map as fields) and the keyframes as visualization_msgs/MarkerArray (frusta,
// covisibility and loop edges). Frame ids: "map" and "camera".
#include <string>
#include <vector>

#include "geometry_msgs/msg/PoseStamped.h"
#include "nav_msgs/msg/Path.h"
#include "sensor_msgs/msg/PointCloud2.h"
#include "tf2_msgs/msg/TFMessage.h"
#include "visualization_msgs/msg/MarkerArray.h"
#include "viz/live_frame.hpp"
#include "viz/map_scene.hpp"

namespace hiveslam::viz::ros {

inline constexpr const char* kMapFrame = "map";
inline constexpr const char* kCameraFrame = "camera";

// A name ROS accepts in a topic: letters, digits and '_' ("lm-2" -> "lm_2").
std::string topicSafe(const std::string& node);
// "rt/hiveslam/<node>/<what>": the DDS name of ROS topic /hiveslam/<node>/<what>.
std::string vizTopic(const std::string& node, const std::string& what);

geometry_msgs::msg::PoseStamped toPoseStamped(const PathPose& pose);
tf2_msgs::msg::TFMessage toTf(const PathPose& pose);
nav_msgs::msg::Path toPath(const std::vector<PathPose>& path, double stamp);
// Fields x, y, z (FLOAT32) and map (UINT32, mapLabel of the map id), 16 bytes a point.
sensor_msgs::msg::PointCloud2 toPointCloud(const MapScene& scene, double stamp);
// Three LINE_LIST markers, sceneLines(): namespace "keyframes" (frusta), "covisibility" and
// "loops".
visualization_msgs::msg::MarkerArray toMarkers(const MapScene& scene, double stamp);

// Back (for `hiveslam view`, which draws a running cluster from its topics).
PathPose fromPoseStamped(const geometry_msgs::msg::PoseStamped& m);
std::vector<PathPose> fromPath(const nav_msgs::msg::Path& m);
// The line lists of toMarkers() (markers of other namespaces or types are skipped).
SceneLines fromMarkers(const visualization_msgs::msg::MarkerArray& m);
// Points from a cloud with float x, y, z at offsets 0, 4, 8 and an optional uint32 "map";
// anything else (another layout, a truncated buffer) gives no points.
MapScene fromPointCloud(const sensor_msgs::msg::PointCloud2& m);

}  // namespace hiveslam::viz::ros
