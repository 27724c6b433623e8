// Records survive encoding and compression, malformed bodies are rejected, and the policy
// D(N, G) gives the paper's four cases.
#include <gtest/gtest.h>

#include <algorithm>
#include <functional>
#include <limits>
#include <random>

#include "distribution/packet.hpp"
#include "distribution/policy.hpp"
#include "distribution/wire_samples.hpp"

namespace hiveslam::distribution {
namespace {

TEST(Wire, KeyframeRoundTrip) {
  const auto m = sampleKeyframe();
  const auto packet = pack(m, 3, 1, m.keyframe.map, 0);
  const auto back = decodeKeyframe(unpack(packet, PacketKind::Keyframe));
  EXPECT_EQ(back.keyframe.id, 42u);
  EXPECT_TRUE(back.keyframe.T_cw.isApprox(m.keyframe.T_cw, 1e-12));
  EXPECT_EQ(back.keyframe.matches, m.keyframe.matches);
  ASSERT_EQ(back.keyframe.frame.size(), 3u);
  EXPECT_EQ(back.keyframe.frame.keypoints[2].octave, 2);
  EXPECT_EQ(back.keyframe.frame.keypoints[1].octave, 1);  // the weak flag rides above the level
  for (int i = 0; i < 3; ++i) EXPECT_EQ(features::isWeakCorner(back.keyframe.frame.keypoints[static_cast<size_t>(i)]), i == 1);
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

// Hostile bytes: every decoder that reads a packet from the network, fed 20,000 mutations of a
// valid message each (bytes flipped, cut, repeated, appended), either decodes it or throws
// WireError: the message is dropped. No other exception, no crash, no read past the end (the
// ASan build runs this too). A mutation that decodes is no error: the body has no checksum,
// and what a malformed record may hold is judged where it is applied.
std::vector<uint8_t> mutate(std::vector<uint8_t> raw, std::mt19937& rng) {
  auto pick = [&](size_t n) { return std::uniform_int_distribution<size_t>(0, n == 0 ? 0 : n - 1)(rng); };
  switch (pick(5)) {
    case 0:  // a few bytes flipped
      for (size_t i = 0, n = 1 + pick(8); i < n && !raw.empty(); ++i) raw[pick(raw.size())] ^= static_cast<uint8_t>(1 + pick(255));
      break;
    case 1:  // cut short
      raw.resize(pick(raw.size() + 1));
      break;
    case 2: {  // a stretch repeated
      const size_t at = pick(raw.size()), len = std::min(raw.size() - at, 1 + pick(64));
      std::vector<uint8_t> chunk(raw.begin() + static_cast<std::ptrdiff_t>(at), raw.begin() + static_cast<std::ptrdiff_t>(at + len));
      raw.insert(raw.begin() + static_cast<std::ptrdiff_t>(at), chunk.begin(), chunk.end());
      break;
    }
    case 3:  // random bytes after it
      for (size_t i = 0, n = 1 + pick(64); i < n; ++i) raw.push_back(static_cast<uint8_t>(pick(256)));
      break;
    default:  // a count or size field made huge: four bytes of 0xff somewhere
      for (size_t i = 0, at = pick(raw.size()); i < 4 && at + i < raw.size(); ++i) raw[at + i] = 0xff;
  }
  return raw;
}

void expectDroppedOrDecoded(const std::vector<uint8_t>& seed, const std::function<void(const std::vector<uint8_t>&)>& decode,
                            const char* what) {
  std::mt19937 rng(7);
  int dropped = 0;
  for (int i = 0; i < 20000; ++i) {
    const auto bytes = mutate(seed, rng);
    try {
      decode(bytes);
    } catch (const WireError&) {
      ++dropped;
    } catch (const std::exception& e) {
      ADD_FAILURE() << what << ", mutation " << i << ": " << e.what();
      return;
    }
  }
  EXPECT_GT(dropped, 1000) << what << ": the mutations should break most messages";
}

TEST(Wire, MutatedMessagesAreDroppedOrDecodedNeverMisread) {
  const MapRecord m = sampleMap();
  const core::Remeasurements r = sampleRemeasurements();
  expectDroppedOrDecoded(encode(sampleKeyframe()), [](const auto& b) { decodeKeyframe(b); }, "keyframe");
  expectDroppedOrDecoded(encode(m), [](const auto& b) { decodeMap(b); }, "map");
  expectDroppedOrDecoded(encode(r), [](const auto& b) { decodeRemeasurements(b); }, "remeasurements");
  // Through the packet layer: the compressed body and its stated size.
  const auto packet = pack(sampleKeyframe(), 1, 1, 7, 0);
  expectDroppedOrDecoded(packet.body, [&](const auto& b) {
    communication::Message msg = packet;
    msg.body = b;
    decodeKeyframe(unpack(msg, PacketKind::Keyframe));
  }, "compressed keyframe");
}

// What fuzz/wire_fuzzer found, kept: a keyframe whose keypoint is not a number is dropped; one
// whose undistorted point is huge but finite (a wide lens can make one) decodes, and its
// feature grid files it at the edge (the cast to a grid cell was undefined for both).
TEST(Wire, FuzzFindingsNotANumberAndHugePoints) {
  auto k = sampleKeyframe();
  k.keyframe.frame.keypoints[1].pt.x = std::numeric_limits<float>::quiet_NaN();
  EXPECT_THROW(decodeKeyframe(encode(k)), WireError);
  k = sampleKeyframe();
  k.keyframe.frame.points[1] = Eigen::Vector2d(-1.6e28, 20.0);
  const KeyFrameMessage back = decodeKeyframe(encode(k));
  std::vector<size_t> near;
  back.keyframe.frame.forEachInRadius(0.0, 20.0, 30.0, [&](size_t i) { near.push_back(i); });
  EXPECT_NE(std::find(near.begin(), near.end(), size_t{0}), near.end());
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
