// The live view's ROS 2 messages: the layouts RViz2 and Foxglove read (PointCloud2 fields and
// strides, Marker line lists, frame ids), and reading them back as `hiveslam view` does.
#include <gtest/gtest.h>

#include <cstring>

#include "communication/dds/topic_discovery.hpp"
#include "viz/ros/ros_messages.hpp"

namespace hiveslam::viz::ros {
namespace {

MapScene twoMaps() {
  MapScene s;
  s.points = {{1.f, 2.f, 3.f, 7}, {-1.f, 0.5f, 4.f, 7}, {0.f, 0.f, 9.f, (uint64_t{2} << 48) | 11}};
  return s;
}

Eigen::Isometry3d pose(double yaw, const Eigen::Vector3d& t) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitY()).toRotationMatrix();
  T.translation() = t;
  return T;
}

TEST(RosMessages, PointCloudIsXyzFloatsAndAMapLabelSixteenBytesAPoint) {
  const auto m = toPointCloud(twoMaps(), 12.25);
  EXPECT_EQ(m.header().frame_id(), "map");
  EXPECT_EQ(m.header().stamp().sec(), 12);
  EXPECT_EQ(m.header().stamp().nanosec(), 250'000'000u);
  ASSERT_EQ(m.fields().size(), 4u);
  const char* names[] = {"x", "y", "z", "map"};
  for (size_t i = 0; i < 4; ++i) {
    EXPECT_EQ(m.fields()[i].name(), names[i]);
    EXPECT_EQ(m.fields()[i].offset(), 4 * i);
    EXPECT_EQ(m.fields()[i].datatype(), i < 3 ? 7 : 6);  // FLOAT32, UINT32
    EXPECT_EQ(m.fields()[i].count(), 1u);
  }
  EXPECT_EQ(m.width(), 3u);
  EXPECT_EQ(m.height(), 1u);
  EXPECT_EQ(m.point_step(), 16u);
  EXPECT_EQ(m.row_step(), 48u);
  ASSERT_EQ(m.data().size(), 48u);
  float z = 0;
  uint32_t label = 0;
  std::memcpy(&z, m.data().data() + 16 + 8, 4);
  std::memcpy(&label, m.data().data() + 32 + 12, 4);
  EXPECT_EQ(z, 4.f);
  EXPECT_EQ(label, mapLabel((uint64_t{2} << 48) | 11));
  EXPECT_NE(mapLabel(7), mapLabel((uint64_t{2} << 48) | 11));
}

TEST(RosMessages, APointCloudReadsBackAndABrokenOneGivesNoPoints) {
  const auto m = toPointCloud(twoMaps(), 1.0);
  const MapScene back = fromPointCloud(m);
  ASSERT_EQ(back.points.size(), 3u);
  EXPECT_EQ(back.points[1].x, -1.f);
  EXPECT_EQ(back.points[1].y, 0.5f);
  EXPECT_EQ(back.points[2].map, mapLabel((uint64_t{2} << 48) | 11));

  auto truncated = m;
  truncated.data().resize(40);
  EXPECT_TRUE(fromPointCloud(truncated).points.empty());
  auto no_z = m;
  no_z.fields().erase(no_z.fields().begin() + 2);
  EXPECT_TRUE(fromPointCloud(no_z).points.empty());
  auto field_outside = m;
  field_outside.fields()[1].offset(14);  // y would run past the 16-byte point
  EXPECT_TRUE(fromPointCloud(field_outside).points.empty());
  auto big_endian = m;
  big_endian.is_bigendian(true);
  EXPECT_TRUE(fromPointCloud(big_endian).points.empty());
}

TEST(RosMessages, PoseAndTfAreTheCameraInTheMapFrame) {
  const PathPose p{3.5, 1, pose(0.3, {1, -2, 0.5})};
  const auto m = toPoseStamped(p);
  EXPECT_EQ(m.header().frame_id(), "map");
  const PathPose back = fromPoseStamped(m);
  EXPECT_NEAR(back.timestamp, 3.5, 1e-9);
  EXPECT_TRUE(back.T_wc.isApprox(p.T_wc, 1e-12));
  const auto tf = toTf(p);
  ASSERT_EQ(tf.transforms().size(), 1u);
  EXPECT_EQ(tf.transforms()[0].header().frame_id(), "map");
  EXPECT_EQ(tf.transforms()[0].child_frame_id(), "camera");
  EXPECT_DOUBLE_EQ(tf.transforms()[0].transform().translation().y(), -2);
  EXPECT_DOUBLE_EQ(tf.transforms()[0].transform().rotation().w(), m.pose().orientation().w());
}

TEST(RosMessages, PathHasEveryPoseInOrder) {
  std::vector<PathPose> path;
  for (int i = 0; i < 5; ++i) path.push_back({i * 0.1, 1, pose(0, {double(i), 0, 0})});
  const auto m = toPath(path, 0.4);
  ASSERT_EQ(m.poses().size(), 5u);
  EXPECT_EQ(m.poses()[3].header().frame_id(), "map");
  EXPECT_DOUBLE_EQ(m.poses()[3].pose().position().x(), 3);
  EXPECT_EQ(fromPath(m).size(), 5u);
}

TEST(RosMessages, KeyframesAreFrustaAndEdgesAsLineLists) {
  MapScene s;
  s.keyframes = {{1, 7, pose(0, {0, 0, 0}).cast<float>()}, {2, 7, pose(0.2, {1, 0, 0}).cast<float>()},
                 {3, 7, pose(0.4, {2, 0, 1}).cast<float>()}};
  s.covisibility = {{0, 1}, {1, 2}};
  s.loops = {{0, 2}};
  const auto m = toMarkers(s, 2.0);
  ASSERT_EQ(m.markers().size(), 3u);
  EXPECT_EQ(m.markers()[0].ns(), "keyframes");
  EXPECT_EQ(m.markers()[0].type(), 5);  // LINE_LIST
  EXPECT_EQ(m.markers()[0].header().frame_id(), "map");
  EXPECT_EQ(m.markers()[0].points().size(), 3u * 16);  // 8 segments a frustum
  EXPECT_GT(m.markers()[0].scale().x(), 0);
  EXPECT_EQ(m.markers()[0].color().a(), 1.f);
  EXPECT_EQ(m.markers()[1].points().size(), 4u);
  EXPECT_EQ(m.markers()[2].points().size(), 2u);
  EXPECT_DOUBLE_EQ(m.markers()[2].points()[1].z(), 1.0);
  // A frustum starts at its keyframe's centre.
  EXPECT_DOUBLE_EQ(m.markers()[0].points()[16].x(), 1.0);
  const SceneLines back = fromMarkers(m);
  EXPECT_EQ(back.frusta.size(), 48u);
  EXPECT_EQ(back.covisibility.size(), 4u);
  EXPECT_EQ(back.loops.size(), 2u);
}

TEST(RosMessages, TopicAndTypeNamesAreRos2s) {
  EXPECT_EQ(vizTopic("lm-2", "points"), "rt/hiveslam/lm_2/points");
  EXPECT_EQ(topicSafe("7up"), "n7up");
  EXPECT_EQ(communication::rosTopicName("rt/hiveslam/tr/pose"), "/hiveslam/tr/pose");
  EXPECT_EQ(communication::rosTopicName("rq/some/serviceRequest"), "");
  EXPECT_EQ(communication::rosTypeName("geometry_msgs::msg::dds_::PoseStamped_"), "geometry_msgs/msg/PoseStamped");
  EXPECT_EQ(communication::rosTypeName("plain::Type"), "plain::Type");
}

}  // namespace
}  // namespace hiveslam::viz::ros
