// Records survive encoding and compression, malformed bodies are rejected, and the policy
// D(N, G) gives the paper's four cases.
#include <gtest/gtest.h>

#include "distribution/packet.hpp"
#include "distribution/policy.hpp"

namespace hiveslam::distribution {
namespace {

KeyFrameMessage sampleKeyframe() {
  KeyFrameMessage m;
  auto& k = m.keyframe;
  k.id = 42;
  k.map = 7;
  k.T_cw.translate(Eigen::Vector3d(1, 2, 3));
  k.T_cw.rotate(Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitY()));
  k.parent = 41;
  k.full = true;
  k.frame.width = 640;
  k.frame.height = 480;
  k.frame.K = {500, 500, 320, 240};
  k.frame.timestamp = 12.5;
  k.frame.descriptors = cv::Mat(3, 32, CV_8U);
  for (int i = 0; i < 3; ++i) {
    k.frame.keypoints.emplace_back(cv::Point2f(10.f * i, 20.f), 31.f, 45.f * i, 0.f, i);
    k.frame.points.emplace_back(10.0 * i, 20.0);
    for (int b = 0; b < 32; ++b) k.frame.descriptors.at<uint8_t>(i, b) = static_cast<uint8_t>(i * 32 + b);
  }
  k.matches = {{0, 100}, {2, 101}};
  PointRecord p;
  p.id = 100;
  p.position = {0.5, -1.25, 3.0};
  p.full = true;
  p.normal = {0, 0, 1};
  p.max_distance = 4;
  m.points.push_back(p);
  return m;
}

TEST(Wire, KeyframeRoundTrip) {
  const auto m = sampleKeyframe();
  const auto packet = pack(m, 3, 1, m.keyframe.map, 0);
  const auto back = decodeKeyframe(unpack(packet, PacketKind::Keyframe));
  EXPECT_EQ(back.keyframe.id, 42u);
  EXPECT_TRUE(back.keyframe.T_cw.isApprox(m.keyframe.T_cw, 1e-12));
  EXPECT_EQ(back.keyframe.matches, m.keyframe.matches);
  ASSERT_EQ(back.keyframe.frame.size(), 3u);
  EXPECT_EQ(back.keyframe.frame.keypoints[2].octave, 2);
  EXPECT_EQ(cv::norm(back.keyframe.frame.descriptors, m.keyframe.frame.descriptors, cv::NORM_HAMMING), 0);
  ASSERT_EQ(back.points.size(), 1u);
  EXPECT_NEAR((back.points[0].position - m.points[0].position).norm(), 0, 1e-6);
}

TEST(Wire, MapRoundTripWithoutUnchangedLinks) {
  MapRecord m;
  m.kind = MapRecord::Kind::Global;
  m.map = 7;
  m.epoch = 3;
  m.batch = 1;
  m.batches = 2;
  m.update = 41;
  KeyFrameRecord k;
  k.id = 5;
  k.links = false;
  m.keyframes.push_back(k);
  m.erased_points = {9, 10};
  m.replaced_points = {{11, 12}};
  m.mapped = {5};
  const auto back = decodeMap(unpack(pack(m, 1, 0, 7, 3), PacketKind::Map));
  EXPECT_EQ(back.kind, MapRecord::Kind::Global);
  EXPECT_EQ(back.batch, 1u);
  EXPECT_EQ(back.update, 41u);
  EXPECT_FALSE(back.keyframes.at(0).links);
  EXPECT_EQ(back.erased_points, m.erased_points);
  EXPECT_EQ(back.replaced_points, m.replaced_points);
  EXPECT_EQ(back.mapped, m.mapped);
}

TEST(Wire, MalformedBodiesAreRejected) {
  const auto raw = encode(sampleKeyframe());
  for (size_t cut : {size_t{0}, size_t{5}, raw.size() / 2, raw.size() - 1}) {
    std::vector<uint8_t> truncated(raw.begin(), raw.begin() + static_cast<std::ptrdiff_t>(cut));
    EXPECT_THROW(decodeKeyframe(truncated), WireError) << cut;
  }
  std::vector<uint8_t> garbage(raw.size(), 0xff);
  EXPECT_THROW(decodeKeyframe(garbage), WireError);
  auto packet = pack(sampleKeyframe(), 1, 1, 7, 0);
  packet.body[packet.body.size() / 2] ^= 0x5a;
  EXPECT_THROW(decodeKeyframe(unpack(packet, PacketKind::Keyframe)), WireError);
  packet.raw_size = 1u << 30;
  EXPECT_THROW(unpack(packet, PacketKind::Keyframe), WireError);
  EXPECT_THROW(unpack(pack(sampleKeyframe(), 1, 1, 7, 0), PacketKind::Map), WireError);
}

TEST(Wire, RemeasurementsRoundTripInSteps) {
  core::Remeasurements r;
  r[42] = {{3, {0.25f, -0.125f}, 1000, 40, 7}, {17, {1.0f / 512, 2.0f}, 5, 42, 17}, {900, {-100.0f, 0.0f}, 123456789, 0, 4000}};
  r[7] = {{0, {0.0f, 0.01f}, 0, 3, 0}};
  r[8] = {{5, {400.0f, 0.0f}, 9, 1, 1}};  // farther than any alignment moves: left out
  r[9] = {{5, {1.0f, 0.0f}, 9, 10, 1}};   // an anchor after its keyframe: left out
  const auto packet = pack(r, 1, 0, 0, 0);
  EXPECT_EQ(packet.kind, static_cast<uint8_t>(PacketKind::Remeasured));
  const core::Remeasurements back = decodeRemeasurements(unpack(packet, PacketKind::Remeasured));
  ASSERT_EQ(back.size(), 4u);
  EXPECT_TRUE(back.at(8).empty());
  EXPECT_TRUE(back.at(9).empty());
  ASSERT_EQ(back.at(42).size(), 3u);
  for (size_t i = 0; i < 3; ++i) {
    EXPECT_EQ(back.at(42)[i].keypoint, r[42][i].keypoint);
    EXPECT_EQ(back.at(42)[i].point, r[42][i].point);
    EXPECT_EQ(back.at(42)[i].anchor_keyframe, r[42][i].anchor_keyframe);
    EXPECT_EQ(back.at(42)[i].anchor_keypoint, r[42][i].anchor_keypoint);
    EXPECT_NEAR(back.at(42)[i].shift.x(), r[42][i].shift.x(), 1.0 / 512);
    EXPECT_NEAR(back.at(42)[i].shift.y(), r[42][i].shift.y(), 1.0 / 512);
  }
  EXPECT_NEAR(back.at(7)[0].shift.y(), 0.01f, 1.0 / 512);
  // Truncated, or keypoints out of order: dropped, never misread.
  const auto raw = encode(r);
  for (size_t cut : {size_t{1}, raw.size() / 2, raw.size() - 1}) {
    std::vector<uint8_t> truncated(raw.begin(), raw.begin() + static_cast<std::ptrdiff_t>(cut));
    EXPECT_THROW(decodeRemeasurements(truncated), WireError) << cut;
  }
  ByteWriter w;
  w.put(uint32_t{1});
  w.varint(10);        // keyframe id
  w.put(uint32_t{2});  // two entries
  for (int i = 0; i < 2; ++i) {
    w.varint(i == 0 ? 5 : 0);  // the second one repeats keypoint 5
    w.put(int16_t{1});
    w.put(int16_t{1});
    w.varint(3);  // point
    w.varint(1);  // anchor: one keyframe back
    w.varint(2);  // anchor keypoint
  }
  EXPECT_THROW(decodeRemeasurements(w.data()), WireError);
  ByteWriter early;
  early.put(uint32_t{1});
  early.varint(10);
  early.put(uint32_t{1});
  early.varint(5);
  early.put(int16_t{1});
  early.put(int16_t{1});
  early.varint(3);
  early.varint(11);  // an anchor before keyframe 0
  early.varint(2);
  EXPECT_THROW(decodeRemeasurements(early.data()), WireError);
}

TEST(Policy, TrackingFollowsThePapersFourCases) {
  using communication::taskBit;
  const uint8_t lm = taskBit(Task::Mapping), lc = taskBit(Task::LoopClosing);
  auto both = decide(Task::Tracking, lm | lc);
  EXPECT_FALSE(both.mapping);
  EXPECT_FALSE(both.loop_closing);
  EXPECT_TRUE(both.keyframes_to_lm);
  auto only_lm = decide(Task::Tracking, lm);
  EXPECT_FALSE(only_lm.mapping);
  EXPECT_FALSE(only_lm.loop_closing);  // LM hosts it
  EXPECT_TRUE(decide(Task::Mapping, 0).loop_closing);
  auto only_lc = decide(Task::Tracking, lc);
  EXPECT_TRUE(only_lc.mapping);
  EXPECT_FALSE(only_lc.loop_closing);
  EXPECT_TRUE(only_lc.keyframes_to_lc);
  auto alone = decide(Task::Tracking, 0);
  EXPECT_TRUE(alone.mapping);
  EXPECT_TRUE(alone.loop_closing);
  EXPECT_TRUE(alone.subscriptions.empty());
}

}  // namespace
}  // namespace hiveslam::distribution
