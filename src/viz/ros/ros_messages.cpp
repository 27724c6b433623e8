#include "viz/ros/ros_messages.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstring>

namespace hiveslam::viz::ros {

namespace {

constexpr uint8_t kFloat32 = 7, kUint32 = 6;  // sensor_msgs/PointField datatypes
constexpr int32_t kLineList = 5, kAdd = 0;    // visualization_msgs/Marker type and action

std_msgs::msg::Header header(double stamp, const char* frame) {
  std_msgs::msg::Header h;
  const double sec = std::floor(std::max(stamp, 0.0));
  h.stamp().sec(static_cast<int32_t>(sec));
  h.stamp().nanosec(static_cast<uint32_t>(std::min((stamp - sec) * 1e9, 999'999'999.0)));
  h.frame_id(frame);
  return h;
}

double seconds(const builtin_interfaces::msg::Time& t) { return t.sec() + t.nanosec() * 1e-9; }

geometry_msgs::msg::Pose toPose(const Eigen::Isometry3d& T) {
  geometry_msgs::msg::Pose p;
  p.position().x(T.translation().x());
  p.position().y(T.translation().y());
  p.position().z(T.translation().z());
  const Eigen::Quaterniond q(T.rotation());
  p.orientation().x(q.x());
  p.orientation().y(q.y());
  p.orientation().z(q.z());
  p.orientation().w(q.w());
  return p;
}

Eigen::Isometry3d fromPose(const geometry_msgs::msg::Pose& p) {
  Eigen::Quaterniond q(p.orientation().w(), p.orientation().x(), p.orientation().y(), p.orientation().z());
  if (q.norm() < 1e-9) q = Eigen::Quaterniond::Identity();
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = q.normalized().toRotationMatrix();
  T.translation() = Eigen::Vector3d(p.position().x(), p.position().y(), p.position().z());
  return T;
}

geometry_msgs::msg::Point point(const Eigen::Vector3f& v) {
  geometry_msgs::msg::Point p;
  p.x(v.x());
  p.y(v.y());
  p.z(v.z());
  return p;
}

visualization_msgs::msg::Marker lineList(const char* ns, int32_t id, double stamp, float width, float r, float g,
                                         float b) {
  visualization_msgs::msg::Marker m;
  m.header(header(stamp, kMapFrame));
  m.ns(ns);
  m.id(id);
  m.type(kLineList);
  m.action(kAdd);
  m.pose().orientation().w(1.0);
  m.scale().x(width);
  m.color().r(r);
  m.color().g(g);
  m.color().b(b);
  m.color().a(1.0f);
  return m;
}

}  // namespace

std::string topicSafe(const std::string& node) {
  std::string s = node.empty() ? std::string("node") : node;
  for (char& c : s)
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '_') c = '_';
  // A ROS name may not start with a digit.
  return std::isdigit(static_cast<unsigned char>(s.front())) ? fmt::format("n{}", s) : s;
}

std::string vizTopic(const std::string& node, const std::string& what) {
  return "rt/hiveslam/" + topicSafe(node) + "/" + what;
}

geometry_msgs::msg::PoseStamped toPoseStamped(const PathPose& pose) {
  geometry_msgs::msg::PoseStamped m;
  m.header(header(pose.timestamp, kMapFrame));
  m.pose(toPose(pose.T_wc));
  return m;
}

tf2_msgs::msg::TFMessage toTf(const PathPose& pose) {
  geometry_msgs::msg::TransformStamped t;
  t.header(header(pose.timestamp, kMapFrame));
  t.child_frame_id(kCameraFrame);
  const auto p = toPose(pose.T_wc);
  t.transform().translation().x(p.position().x());
  t.transform().translation().y(p.position().y());
  t.transform().translation().z(p.position().z());
  t.transform().rotation(p.orientation());
  tf2_msgs::msg::TFMessage m;
  m.transforms().push_back(t);
  return m;
}

nav_msgs::msg::Path toPath(const std::vector<PathPose>& path, double stamp) {
  nav_msgs::msg::Path m;
  m.header(header(stamp, kMapFrame));
  m.poses().reserve(path.size());
  for (const auto& p : path) m.poses().push_back(toPoseStamped(p));
  return m;
}

sensor_msgs::msg::PointCloud2 toPointCloud(const MapScene& scene, double stamp) {
  sensor_msgs::msg::PointCloud2 m;
  m.header(header(stamp, kMapFrame));
  const char* names[] = {"x", "y", "z", "map"};
  for (uint32_t i = 0; i < 4; ++i) {
    sensor_msgs::msg::PointField f;
    f.name(names[i]);
    f.offset(4 * i);
    f.datatype(i < 3 ? kFloat32 : kUint32);
    f.count(1);
    m.fields().push_back(f);
  }
  constexpr uint32_t kStep = 16;
  const auto n = static_cast<uint32_t>(scene.points.size());
  m.height(1);
  m.width(n);
  m.is_bigendian(false);
  m.point_step(kStep);
  m.row_step(kStep * n);
  m.is_dense(true);
  m.data().resize(static_cast<size_t>(kStep) * n);
  uint8_t* out = m.data().data();
  for (const auto& p : scene.points) {
    const float xyz[3] = {p.x, p.y, p.z};
    const uint32_t label = mapLabel(p.map);
    std::memcpy(out, xyz, 12);
    std::memcpy(out + 12, &label, 4);
    out += kStep;
  }
  return m;
}

visualization_msgs::msg::MarkerArray toMarkers(const MapScene& scene, double stamp) {
  const SceneLines l = sceneLines(scene);
  // Lines a tenth of a frustum wide: the frustum's first segment is its centre to a corner.
  const float size = l.frusta.size() >= 2 ? (l.frusta[1] - l.frusta[0]).norm() / 1.5f : 0.05f;
  auto list = [&](const char* ns, int32_t id, const std::vector<Eigen::Vector3f>& ends, float width, float r, float g,
                  float b) {
    auto m = lineList(ns, id, stamp, width, r, g, b);
    m.points().reserve(ends.size());
    for (const auto& e : ends) m.points().push_back(point(e));
    return m;
  };
  visualization_msgs::msg::MarkerArray a;
  a.markers().push_back(list("keyframes", 0, l.frusta, size / 10, 0.2f, 0.4f, 1.0f));
  a.markers().push_back(list("covisibility", 1, l.covisibility, size / 20, 0.1f, 0.8f, 0.2f));
  a.markers().push_back(list("loops", 2, l.loops, size / 20, 1.0f, 0.2f, 0.2f));
  return a;
}

SceneLines fromMarkers(const visualization_msgs::msg::MarkerArray& m) {
  SceneLines l;
  for (const auto& marker : m.markers()) {
    if (marker.type() != kLineList) continue;
    std::vector<Eigen::Vector3f>* out = marker.ns() == "keyframes"      ? &l.frusta
                                        : marker.ns() == "covisibility" ? &l.covisibility
                                        : marker.ns() == "loops"        ? &l.loops
                                                                        : nullptr;
    if (!out) continue;
    const size_t even = marker.points().size() / 2 * 2;
    for (size_t i = 0; i < even; ++i) {
      const auto& p = marker.points()[i];
      out->emplace_back(static_cast<float>(p.x()), static_cast<float>(p.y()), static_cast<float>(p.z()));
    }
  }
  return l;
}

PathPose fromPoseStamped(const geometry_msgs::msg::PoseStamped& m) {
  return {seconds(m.header().stamp()), 0, fromPose(m.pose())};
}

std::vector<PathPose> fromPath(const nav_msgs::msg::Path& m) {
  std::vector<PathPose> path;
  path.reserve(m.poses().size());
  for (const auto& p : m.poses()) path.push_back(fromPoseStamped(p));
  return path;
}

MapScene fromPointCloud(const sensor_msgs::msg::PointCloud2& m) {
  MapScene s;
  int x = -1, y = -1, z = -1, map = -1;
  for (const auto& f : m.fields()) {
    const int off = static_cast<int>(f.offset());
    if (f.name() == "x" && f.datatype() == kFloat32) x = off;
    if (f.name() == "y" && f.datatype() == kFloat32) y = off;
    if (f.name() == "z" && f.datatype() == kFloat32) z = off;
    if (f.name() == "map" && f.datatype() == kUint32) map = off;
  }
  const size_t step = m.point_step();
  const size_t n = static_cast<size_t>(m.width()) * m.height();
  if (x < 0 || y < 0 || z < 0 || m.is_bigendian() || step < 12 || n == 0 || m.data().size() / step < n) return s;
  const auto fits = [&](int off, size_t bytes) { return static_cast<size_t>(off) + bytes <= step; };
  if (!fits(x, 4) || !fits(y, 4) || !fits(z, 4) || (map >= 0 && !fits(map, 4))) return s;
  s.points.resize(n);
  const uint8_t* d = m.data().data();
  for (size_t i = 0; i < n; ++i, d += step) {
    auto& p = s.points[i];
    std::memcpy(&p.x, d + x, 4);
    std::memcpy(&p.y, d + y, 4);
    std::memcpy(&p.z, d + z, 4);
    uint32_t label = 0;
    if (map >= 0) std::memcpy(&label, d + map, 4);
    p.map = label;
  }
  return s;
}

}  // namespace hiveslam::viz::ros
