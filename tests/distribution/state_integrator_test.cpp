// A local map or a keyframe that its sender made before it applied this node's latest global
// map comes in the old coordinate frame (its label says which). Its new points must land where
// the correction would have put them: a point left at its old position sits centimetres off in
// a map a loop closure just moved, and the next loop search matches it with a wrong scale.
// On the same two-keyframe map: which keyframes a local map acknowledges as mapped.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <optional>
#include <thread>

#include "communication/inproc/inproc_network.hpp"
#include "core/camera/pinhole_radtan.hpp"
#include "core/mapping/keyframe_insertion.hpp"
#include "core/system/slam_system.hpp"
#include "distribution/map_handler.hpp"
#include "distribution/packet.hpp"
#include "distribution/state_integrator.hpp"
#include "eventually.hpp"

namespace hiveslam::distribution {
namespace {

constexpr Id kMap = 7, kFirst = 11, kSecond = 12, kNewPoint = 500;
constexpr int kPoints = 30;

core::Frame featureFrame(size_t n) {
  core::Frame f;
  f.keypoints.assign(n, cv::KeyPoint(100.f, 100.f, 31.f));
  f.points.assign(n, Eigen::Vector2d(100, 100));
  f.descriptors = cv::Mat::zeros(static_cast<int>(n), 32, CV_8U);
  f.K = {400, 400, 320, 240};
  f.width = 640;
  f.height = 480;
  f.buildGrid();
  return f;
}

Eigen::Isometry3d poseAt(double x) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(0.1 * x, Eigen::Vector3d::UnitY()).toRotationMatrix();
  T.translation() = Eigen::Vector3d(-x, 0.1, 0);
  return T;
}

Eigen::Vector3d pointAt(int i) { return {-1.0 + 0.07 * i, 0.3 * std::sin(i), 3.0 + 0.05 * i}; }

// The pose that sees the world moved by S as T saw it, the map scaled by S.s around it.
Eigen::Isometry3d moved(const Eigen::Isometry3d& T, const core::Sim3& S) {
  return (core::Sim3(Eigen::Quaterniond::Identity(), Eigen::Vector3d::Zero(), S.s) * core::Sim3(T) * S.inverse())
      .toPose();
}

// A map handler's sender and a receiver on an in-process network; the receiver decodes what
// comes on the given map topics.
struct MapTopics {
  explicit MapTopics(std::initializer_list<communication::Topic> topics) {
    receiver->start({}, [](const communication::PeerInfo&, bool) {});
    for (auto topic : topics)
      receiver->subscribe(topic, [this, topic](communication::Message&& m) {
        std::lock_guard lock(mutex);
        received.emplace_back(topic, decodeMap(unpack(m, PacketKind::Map)));
      });
    sender->start({}, [](const communication::PeerInfo&, bool) {});
  }
  ~MapTopics() {
    sender->stop();
    receiver->stop();
  }
  size_t count(std::optional<communication::Topic> topic = std::nullopt) {
    std::lock_guard lock(mutex);
    return static_cast<size_t>(std::count_if(received.begin(), received.end(), [&](const auto& r) { return !topic || r.first == *topic; }));
  }
  std::vector<MapRecord> records() {
    std::lock_guard lock(mutex);
    std::vector<MapRecord> out;
    for (const auto& r : received) out.push_back(r.second);
    return out;
  }
  communication::InProcNetwork network;
  std::unique_ptr<communication::InProcTransport> sender = network.endpoint(), receiver = network.endpoint();
  std::mutex mutex;
  std::vector<std::pair<communication::Topic, MapRecord>> received;
};

class EpochLabels : public ::testing::Test {
 protected:
  void SetUp() override {
    for (Id kf : {kFirst, kSecond}) {
      KeyFrameMessage m;
      m.keyframe.id = kf;
      m.keyframe.map = kMap;
      m.keyframe.full = true;
      m.keyframe.frame = featureFrame(kPoints + 1);
      m.keyframe.T_cw = poseAt(kf == kFirst ? 0.0 : 0.4);
      if (kf == kSecond) m.keyframe.parent = kFirst;
      for (int i = 0; i < kPoints; ++i) {
        m.keyframe.matches.emplace_back(i, 100 + i);
        if (kf == kFirst) {
          PointRecord p;
          p.id = 100 + i;
          p.position = pointAt(i);
          p.full = true;
          p.first_keyframe = kFirst;
          m.points.push_back(p);
        }
      }
      const auto added = integrator_.addKeyframe(m, 0);
      ASSERT_TRUE(added.keyframe);
      std::lock_guard lock(added.map->mutex);
      core::insertKeyframe(*added.map, *added.keyframe, slam_.scales(), &slam_.database());
    }
  }

  // Keyframe `kf`'s record at T_cw, without links.
  static KeyFrameRecord keyframeRecord(Id kf, const Eigen::Isometry3d& T_cw) {
    KeyFrameRecord k;
    k.id = kf;
    k.map = kMap;
    k.links = false;
    k.T_cw = T_cw;
    return k;
  }

  // The map's first `count` points, moved by S.
  static void addPoints(MapRecord& m, int count, const core::Sim3& S = core::Sim3()) {
    for (int i = 0; i < count; ++i) {
      PointRecord p;
      p.id = 100 + i;
      p.position = S * pointAt(i);
      m.points.push_back(p);
    }
  }

  // The loop closure: the whole map moves by S from where it was made (the global map of
  // `epoch`).
  void correct(const core::Sim3& S, uint64_t epoch = 1) {
    MapRecord g;
    g.kind = MapRecord::Kind::Global;
    g.map = kMap;
    g.epoch = epoch;
    for (Id kf : {kFirst, kSecond}) g.keyframes.push_back(keyframeRecord(kf, moved(poseAt(kf == kFirst ? 0.0 : 0.4), S)));
    addPoints(g, kPoints, S);
    integrator_.applyGlobal({g}, false);
  }

  // LM's authoritative snapshot of the map at epoch 1: both keyframes, a keyframe `newer` made
  // since, and every point but the last, which the sender no longer has.
  static MapRecord snapshotWithoutLastPoint(Id newer) {
    MapRecord g;
    g.kind = MapRecord::Kind::Global;
    g.map = kMap;
    g.epoch = 1;
    for (Id kf : {kFirst, kSecond, newer})
      g.keyframes.push_back(keyframeRecord(kf, poseAt(kf == kFirst ? 0.0 : kf == kSecond ? 0.4 : 0.8)));
    addPoints(g, kPoints - 1);
    return g;
  }

  // LM's local map of epoch 0: the window as it was, and one new point, all in the old frame.
  MapRecord staleLocalMap(const Eigen::Vector3d& new_point, bool with_keyframes = true) const {
    MapRecord m;
    m.map = kMap;
    m.epoch = 0;
    if (with_keyframes)
      for (Id kf : {kFirst, kSecond}) m.keyframes.push_back(keyframeRecord(kf, poseAt(kf == kFirst ? 0.0 : 0.4)));
    addPoints(m, kPoints);
    PointRecord p;
    p.id = kNewPoint;
    p.position = new_point;
    p.full = true;
    p.first_keyframe = kSecond;
    m.points.push_back(p);
    return m;
  }

  // Keyframe 13, which tracking posed 0.1 m on from the second keyframe, whose pose there
  // was T_second: the frame the message is in.
  static KeyFrameMessage keyframeOnSecond(const Eigen::Isometry3d& T_second) {
    KeyFrameMessage m;
    m.keyframe.id = 13;
    m.keyframe.map = kMap;
    m.keyframe.full = true;
    m.keyframe.frame = featureFrame(kPoints + 1);
    m.keyframe.T_made_from.translation() = Eigen::Vector3d(-0.1, 0, 0);
    m.keyframe.T_cw = m.keyframe.T_made_from * T_second;
    m.keyframe.made_from = kSecond;
    return m;
  }

  // The same, seeing a new point at (0.3, 0.2, 4.5) in the message's frame.
  static KeyFrameMessage keyframeWithPointOnSecond(const Eigen::Isometry3d& T_second) {
    KeyFrameMessage m = keyframeOnSecond(T_second);
    m.keyframe.matches.emplace_back(kPoints, kNewPoint);
    PointRecord p;
    p.id = kNewPoint;
    p.position = Eigen::Vector3d(0.3, 0.2, 4.5);
    p.full = true;
    p.first_keyframe = 13;
    m.points.push_back(p);
    return m;
  }

  static void expectPose(const core::KeyFrame& kf, const Eigen::Isometry3d& want) {
    EXPECT_LT((kf.T_cw.translation() - want.translation()).norm(), 1e-9);
    EXPECT_LT(Eigen::AngleAxisd(want.linear().transpose() * kf.T_cw.linear()).angle(), 1e-9);
  }

  std::shared_ptr<core::KeyFrame> keyframeHere(Id id) {
    auto map = slam_.findMap(kMap);
    std::lock_guard lock(map->mutex);
    return map->keyframes.at(id);
  }

  std::optional<Eigen::Vector3d> pointHere(Id id) {
    auto map = slam_.findMap(kMap);
    std::lock_guard lock(map->mutex);
    auto it = map->points.find(id);
    if (it == map->points.end()) return std::nullopt;
    return it->second->position;
  }

  core::SlamSystem slam_{core::SlamSettings{},
                         std::make_shared<camera::PinholeRadTan>(640, 480, 400, 400, 320, 240),
                         core::SlamSystem::Mode::Offline};
  Observer observer_;
  StateIntegrator integrator_{slam_, observer_};
};

TEST_F(EpochLabels, NewPointsFollowTheCorrectionScaleIncluded) {
  const core::Sim3 S(Eigen::Quaterniond(Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitZ())), {2.0, -1.0, 0.5}, 1.2);
  correct(S);
  ASSERT_LT((*pointHere(100) - S * pointAt(0)).norm(), 1e-9);  // the correction itself landed

  const Eigen::Vector3d q(0.2, -0.1, 4.0);
  integrator_.applyLocal(staleLocalMap(q));
  const auto here = pointHere(kNewPoint);
  ASSERT_TRUE(here);
  EXPECT_LT((*here - S * q).norm(), 1e-9) << "at " << here->transpose() << ", expected " << (S * q).transpose();
  EXPECT_EQ(integrator_.stalePointsCarried(), 1u);
  // The points this node already had keep their corrected positions.
  EXPECT_LT((*pointHere(105) - S * pointAt(5)).norm(), 1e-9);
}

TEST_F(EpochLabels, AFreshLocalMapIsTakenAsItIs) {
  const core::Sim3 S(Eigen::Quaterniond::Identity(), {1.0, 0, 0}, 1.1);
  correct(S);
  {
    auto map = slam_.findMap(kMap);
    std::lock_guard lock(map->mutex);
    EXPECT_EQ(integrator_.label(*map), 1u);  // what this node's own records now carry
  }
  MapRecord m = staleLocalMap({0.2, -0.1, 4.0});
  m.epoch = 1;  // made after the sender applied the same correction: already in the new frame
  integrator_.applyLocal(m);
  EXPECT_LT((*pointHere(kNewPoint) - Eigen::Vector3d(0.2, -0.1, 4.0)).norm(), 1e-12);
  EXPECT_EQ(integrator_.stalePointsCarried(), 0u);
}

TEST_F(EpochLabels, AKeyframeMadeBeforeTheCorrectionIsRePosedWithItsPointsScaleIncluded) {
  const core::Sim3 S(Eigen::Quaterniond(Eigen::AngleAxisd(0.2, Eigen::Vector3d::UnitX())), {0.5, 2.0, -1.0}, 1.2);
  correct(S);
  // Tracking posed it in the old frame; it brings a point.
  const KeyFrameMessage m = keyframeWithPointOnSecond(poseAt(0.4));
  const PointRecord& p = m.points.front();
  const auto added = integrator_.addKeyframe(m, 0);
  ASSERT_TRUE(added.keyframe);
  expectPose(*added.keyframe, moved(m.keyframe.T_cw, S));
  EXPECT_LT((*pointHere(kNewPoint) - S * p.position).norm(), 1e-9);
}

// LC takes only the relay of its own latest update; a newcomer's snapshot labelled with an
// older one is applied as a stale local map. It may bring a keyframe LC never got (the one a
// mapping node mapped as it died): that keyframe is added, re-posed into the current frame,
// and linked to the snapshot's points.
TEST_F(EpochLabels, ASnapshotFromAnOlderFrameStillBringsTheKeyframesThisNodeLacks) {
  const core::Sim3 S(Eigen::Quaterniond(Eigen::AngleAxisd(0.2, Eigen::Vector3d::UnitX())), {0.5, 2.0, -1.0}, 1.2);
  correct(S);
  MapRecord snapshot = staleLocalMap(Eigen::Vector3d(0.3, 0.2, 4.5));
  snapshot.kind = MapRecord::Kind::Global;
  snapshot.points.back().first_keyframe = 13;
  KeyFrameMessage lacked = keyframeOnSecond(poseAt(0.4));
  lacked.keyframe.matches.emplace_back(kPoints, kNewPoint);
  snapshot.keyframes.push_back(lacked.keyframe);  // with its features, as a snapshot carries it

  integrator_.applyLocal(snapshot);
  const auto added = integrator_.addMissing({snapshot});
  ASSERT_EQ(added.size(), 1u);
  EXPECT_EQ(added[0].keyframe->id, 13u);
  expectPose(*added[0].keyframe, moved(lacked.keyframe.T_cw, S));
  EXPECT_LT((*pointHere(kNewPoint) - S * Eigen::Vector3d(0.3, 0.2, 4.5)).norm(), 1e-9);
  {
    std::lock_guard lock(added[0].map->mutex);
    core::insertKeyframe(*added[0].map, *added[0].keyframe, slam_.scales(), &slam_.database());
    ASSERT_TRUE(added[0].keyframe->points[kPoints]);
    EXPECT_EQ(added[0].keyframe->points[kPoints]->id, kNewPoint);
    EXPECT_EQ(added[0].keyframe->points[kPoints]->observations.count(added[0].keyframe.get()), 1u);
  }
  EXPECT_TRUE(integrator_.addMissing({snapshot}).empty());  // held now
}

// TR sent a keyframe to the LM that had just joined, and the hand-over snapshot taken after
// brought it first. The message must still give it to local mapping (it once was dropped as
// known: nobody mapped it, and TR waited for an acknowledgement that never came), with the
// snapshot's pose, which is the newer.
TEST_F(EpochLabels, AKeyframeThatCameFirstInASnapshotIsStillReturnedForItsModule) {
  const core::Sim3 S(Eigen::Quaterniond::Identity(), {0.2, 0, 0}, 1.0);
  correct(S);
  KeyFrameMessage m;
  m.keyframe.id = kSecond;
  m.keyframe.map = kMap;
  m.keyframe.full = true;
  m.keyframe.frame = featureFrame(kPoints + 1);
  m.keyframe.T_cw = poseAt(0.4);  // where tracking put it, before the correction
  const auto added = integrator_.addKeyframe(m, 0);
  ASSERT_TRUE(added.keyframe);
  EXPECT_TRUE(added.held);
  expectPose(*added.keyframe, moved(poseAt(0.4), S));
}

// A mapping node that just joined got keyframe 13 first in the hand-over snapshot and culled
// it as its mapping went on; then 13's own message came out of the queue. Made again from the
// message, it lived on in this node's map alone (erased at every other node and in this
// node's S_full; TR ended an ASan run a keyframe short). It stays erased: returned marked bad,
// local mapping acknowledges it to its maker and maps nothing.
TEST_F(EpochLabels, AKeyframeErasedHereBeforeItsMessageWasTakenStaysErased) {
  const KeyFrameMessage m = keyframeOnSecond(poseAt(0.4));
  const auto first = integrator_.addKeyframe(m, 0);
  ASSERT_TRUE(first.keyframe);
  {
    std::lock_guard lock(first.map->mutex);
    core::insertKeyframe(*first.map, *first.keyframe, slam_.scales(), &slam_.database());
  }
  MapRecord culled;
  culled.map = kMap;
  culled.erased_keyframes = {13};
  integrator_.applyLocal(culled);
  ASSERT_EQ(observer_.digest().keyframes.count(13), 0u);

  const auto again = integrator_.addKeyframe(m, 0);
  ASSERT_TRUE(again.keyframe) << "nothing returned: local mapping would never acknowledge it";
  EXPECT_TRUE(again.keyframe->bad);
  EXPECT_FALSE(again.held);
  std::lock_guard lock(again.map->mutex);
  core::insertKeyframe(*again.map, *again.keyframe, slam_.scales(), &slam_.database());
  EXPECT_EQ(again.map->keyframes.count(13), 0u) << "made again in this node's map";
  EXPECT_EQ(observer_.digest().keyframes.count(13), 0u);
}

// A sender many global updates behind (each global map takes a second or more to send, and
// global BAs follow one another): its label is older than every one this node keeps. It is
// still from an old frame, and its keyframe is re-posed, not taken as it is.
TEST_F(EpochLabels, AKeyframeFromFarBehindIsStillRePosed) {
  const core::Sim3 S1(Eigen::Quaterniond::Identity(), {0.5, 0, 0}, 1.0);
  const core::Sim3 S2(Eigen::Quaterniond(Eigen::AngleAxisd(0.2, Eigen::Vector3d::UnitX())), {0.5, 2.0, -1.0}, 1.0);
  correct(S1, 1);
  correct(S2, 2);
  for (uint64_t e = 3; e < 3 + StateIntegrator::kLabelsKept; ++e) correct(S2, e);  // no further move
  const KeyFrameMessage m = keyframeOnSecond(moved(poseAt(0.4), S1));  // in the frame of label 1
  const auto added = integrator_.addKeyframe(m, 1);
  ASSERT_TRUE(added.keyframe);
  expectPose(*added.keyframe, m.keyframe.T_made_from * moved(poseAt(0.4), S2));
}

// Tracking posed a keyframe in a map that loop closing has since merged into another: the merge
// reached this node first. The keyframe goes into the merged map, re-posed from the keyframe it
// was posed from and with its point moved by the merge; dropped, it lived on at TR alone (a CI
// run ended with TR one keyframe ahead of LM and LC).
TEST_F(EpochLabels, AKeyframeOfAMapMergedSinceGoesIntoTheMergedMap) {
  constexpr Id kOther = 8, kOtherFirst = 21;
  KeyFrameMessage first;
  first.keyframe.id = kOtherFirst;
  first.keyframe.map = kOther;
  first.keyframe.full = true;
  first.keyframe.frame = featureFrame(kPoints + 1);
  first.keyframe.T_cw = poseAt(2.0);
  ASSERT_TRUE(integrator_.addKeyframe(first, 0).keyframe);
  // The merge: this node's map moves by S into the other map's frame.
  const core::Sim3 S(Eigen::Quaterniond(Eigen::AngleAxisd(0.4, Eigen::Vector3d::UnitY())), {1.0, 0.5, -2.0}, 0.8);
  MapRecord g;
  g.kind = MapRecord::Kind::Global;
  g.map = kOther;
  g.epoch = 1;
  g.merged_maps = {kMap};
  g.keyframes.push_back(keyframeRecord(kOtherFirst, poseAt(2.0)));
  g.keyframes.back().map = kOther;
  for (Id kf : {kFirst, kSecond}) {
    g.keyframes.push_back(keyframeRecord(kf, moved(poseAt(kf == kFirst ? 0.0 : 0.4), S)));
    g.keyframes.back().map = kOther;
  }
  addPoints(g, kPoints, S);
  ASSERT_TRUE(integrator_.applyGlobal({g}, false));
  ASSERT_TRUE(slam_.findMap(kMap)->merged_into.load());

  // Labelled 0: the merged map never had a correction.
  const KeyFrameMessage m = keyframeWithPointOnSecond(poseAt(0.4));
  const PointRecord& p = m.points.front();
  const auto added = integrator_.addKeyframe(m, 0);
  ASSERT_TRUE(added.keyframe);
  ASSERT_TRUE(added.map);
  EXPECT_EQ(added.map->id, kOther);
  expectPose(*added.keyframe, moved(m.keyframe.T_cw, S));
  std::lock_guard lock(added.map->mutex);
  ASSERT_TRUE(added.map->points.count(kNewPoint));
  EXPECT_LT((added.map->points.at(kNewPoint)->position - S * p.position).norm(), 1e-9);
  const auto recorded = observer_.digest().keyframes;  // S_full has it where the map has it
  ASSERT_TRUE(recorded.count(13));
  EXPECT_LT((recorded.at(13).translation() - added.keyframe->T_cw.translation()).norm(), 1e-9);
}

// The other way round: the sender applied a global map that is still on its way here, so its
// local map is in a newer frame and waits for it (DistributedNode holds it). Meanwhile its new
// point is lent to tracking, carried into this node's frame and linked to the keyframe that
// sees it; poses and known points stay as they are. When the global map lands, the point moves
// with it, and the record, applied then, puts it where the sender has it.
TEST_F(EpochLabels, ALocalMapAheadOfItsGlobalMapLendsItsNewPointInTheCurrentFrame) {
  const core::Sim3 S(Eigen::Quaterniond(Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitZ())), {2.0, -1.0, 0.5}, 1.2);
  const Eigen::Vector3d q(0.2, -0.1, 4.0);
  MapRecord m = staleLocalMap(S * q);
  m.epoch = 1;
  for (auto& k : m.keyframes) {
    k.T_cw = moved(k.T_cw, S);
    if (k.id != kSecond) continue;
    k.links = true;
    k.parent = kFirst;
    for (int i = 0; i < kPoints; ++i) k.matches.emplace_back(i, 100 + i);
    k.matches.emplace_back(kPoints, kNewPoint);
  }
  for (auto& p : m.points)
    if (p.id != kNewPoint) p.position = S * p.position;

  integrator_.applyAhead(m);
  const auto lent = pointHere(kNewPoint);
  ASSERT_TRUE(lent);
  EXPECT_LT((*lent - q).norm(), 1e-9) << "at " << lent->transpose() << ", expected " << q.transpose();
  EXPECT_LT((*pointHere(105) - pointAt(5)).norm(), 1e-12);  // known points wait for the record
  {
    auto map = slam_.findMap(kMap);
    std::lock_guard lock(map->mutex);
    const core::KeyFrame& second = *map->keyframes.at(kSecond);
    expectPose(second, poseAt(0.4));
    ASSERT_TRUE(second.points[kPoints]);
    EXPECT_EQ(second.points[kPoints]->id, kNewPoint);
  }

  correct(S, 1);
  EXPECT_LT((*pointHere(kNewPoint) - S * q).norm(), 1e-9);  // it moved with the correction
  integrator_.applyLocal(m);
  EXPECT_LT((*pointHere(kNewPoint) - S * q).norm(), 1e-12);
  EXPECT_LT((*pointHere(105) - S * pointAt(5)).norm(), 1e-9);
}

TEST_F(EpochLabels, ANewPointWithNoKeyframeToCarryItWaitsForAFreshRecord) {
  correct(core::Sim3(Eigen::Quaterniond::Identity(), {1.0, 0, 0}, 1.1));
  integrator_.applyLocal(staleLocalMap({0.2, -0.1, 4.0}, false));
  EXPECT_FALSE(pointHere(kNewPoint));
}

// Tracking makes its next keyframe once the gateway acknowledges its last as mapped. A local
// map carries a keyframe's covisible neighbours too, the newest of which may not be mapped
// yet: only the keyframe marked with `acknowledge` may count, or tracking runs ahead of
// mapping and poses keyframes in a map without their predecessors' new points.
TEST_F(EpochLabels, ALocalMapAcknowledgesOnlyTheKeyframeMappedNotItsNeighbours) {
  MapTopics net{communication::Topic::LmMap};
  SentLedger ledger;
  MapHandler handler(*net.sender, integrator_, observer_, ledger, DistributionSettings{}, 2, {});
  const auto map = slam_.findMap(kMap);
  const auto first = keyframeHere(kFirst), second = keyframeHere(kSecond);
  handler.markDirty(map, *first, communication::Topic::LmMap, -1, true);
  handler.finish();
  std::set<Id> carried, mapped;
  for (const auto& r : net.records()) {
    for (const auto& k : r.keyframes) carried.insert(k.id);
    mapped.insert(r.mapped.begin(), r.mapped.end());
  }
  EXPECT_EQ(carried, (std::set<Id>{kFirst, kSecond}));  // the neighbour rides along
  EXPECT_EQ(mapped, std::set<Id>{kFirst});

  // A keyframe local mapping culled before its batch left is still acknowledged.
  MapHandler again(*net.sender, integrator_, observer_, ledger, DistributionSettings{}, 2, {});
  {
    std::lock_guard lock(map->mutex);
    second->bad = true;
  }
  const size_t before = net.count();
  again.markDirty(map, *second, communication::Topic::LmMap, 0, true);
  again.finish();
  const auto records = net.records();
  ASSERT_GT(records.size(), before);
  EXPECT_EQ(records.back().mapped, std::vector<Id>{kSecond});
}


// Global updates of one map can come faster than a whole map takes to send (global BAs back to
// back on a large map). A receiver drops an update it did not get whole, so each one begun
// must be finished: cut short for the next, none would ever arrive. Updates that are still
// waiting meanwhile collapse into the newest.
TEST_F(EpochLabels, GlobalMapsBegunAreFinishedWhenNewerOnesComeFasterThanTheyGoOut) {
  MapTopics net{communication::Topic::LmMap};
  SentLedger ledger;
  DistributionSettings settings;
  settings.global_batch = 1;          // one keyframe a batch: two batches for the two keyframes
  settings.global_batch_gap_ms = 40;  // a whole map every 80 ms or so
  MapHandler handler(*net.sender, integrator_, observer_, ledger, settings, 2, {});
  const auto map = slam_.findMap(kMap);
  constexpr uint64_t kUpdates = 12;
  for (uint64_t e = 1; e <= kUpdates; ++e) {
    handler.sendGlobal(map, e, communication::Topic::LmMap, {});
    std::this_thread::sleep_for(std::chrono::milliseconds(25));  // three updates per whole map
  }
  handler.finish();
  std::map<uint64_t, std::set<uint32_t>> batches_of;  // epoch -> batches received
  std::map<uint64_t, uint32_t> expected;
  for (const auto& r : net.records()) {
    batches_of[r.epoch].insert(r.batch);
    expected[r.epoch] = r.batches;
  }
  ASSERT_FALSE(batches_of.empty());
  for (const auto& [epoch, got] : batches_of) EXPECT_EQ(got.size(), expected[epoch]) << "epoch " << epoch << " cut short";
  EXPECT_EQ(batches_of.rbegin()->first, kUpdates);  // the newest went out, whole
  // (How many in between depends on the machine's timing: about four here, the waiting ones
  // collapsed into newer ones.)
  EXPECT_EQ(handler.globalMapsSent(), static_cast<int>(batches_of.size()));
}

// Tracking waits for its keyframe's acknowledgement, and the points that keyframe made are what
// it tracks next: the batch that acknowledges it goes at once, though the batches local BA marks
// go local_batch_gap_ms apart (here 3 s: the acknowledgement must come in half that).
TEST_F(EpochLabels, AnAcknowledgementGoesAtOnceThoughTheLastBatchJustWent) {
  MapTopics net{communication::Topic::LmMap};
  SentLedger ledger;
  DistributionSettings settings;
  settings.local_batch_gap_ms = 3000;
  MapHandler handler(*net.sender, integrator_, observer_, ledger, settings, 2, {});
  const auto map = slam_.findMap(kMap);
  handler.markDirty(map, *keyframeHere(kFirst), communication::Topic::LmMap);  // after a local BA: the window
  ASSERT_TRUE(hiveslam::testing::eventually([&] { return net.count() == 1; }, std::chrono::seconds(10)));
  handler.markDirty(map, *keyframeHere(kSecond), communication::Topic::LmMap, 0, /*acknowledge=*/true);
  ASSERT_TRUE(hiveslam::testing::eventually([&] { return net.count() == 2; }, std::chrono::milliseconds(1500)))
      << "the acknowledgement waited for the gap";
  EXPECT_EQ(net.records().back().mapped, std::vector<Id>{kSecond});
  // A window marked dirty without an acknowledgement still waits for the gap.
  handler.markDirty(map, *keyframeHere(kFirst), communication::Topic::LmMap);
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  EXPECT_EQ(net.count(), 2u) << "a batch went before the gap was out";
}

// LC's map topic carries its global maps only, so nothing waits behind them there: their
// batches go back to back (lc_global_batch_gap_ms 0), while LM's relay, which shares its
// topic with the local maps tracking waits for, keeps the pacing.
TEST_F(EpochLabels, LoopClosingsGlobalMapsGoBackToBackTheRelayIsPaced) {
  using communication::Topic;
  MapTopics net{Topic::LcMap, Topic::LmMap};
  SentLedger ledger;
  DistributionSettings settings;
  settings.global_batch = 1;  // two batches for the two keyframes
  settings.global_batch_gap_ms = 3000;
  MapHandler handler(*net.sender, integrator_, observer_, ledger, settings, 3, {});
  handler.sendGlobal(slam_.findMap(kMap), 1, Topic::LcMap, {});
  EXPECT_TRUE(hiveslam::testing::eventually([&] { return net.count(Topic::LcMap) == 2; }, std::chrono::milliseconds(1500)))
      << "LC's second batch waited for the gap";
  handler.sendGlobal(slam_.findMap(kMap), 2, Topic::LmMap, {});
  ASSERT_TRUE(hiveslam::testing::eventually([&] { return net.count(Topic::LmMap) == 1; }, std::chrono::seconds(10)));
  std::this_thread::sleep_for(std::chrono::milliseconds(300));
  EXPECT_EQ(net.count(Topic::LmMap), 1u) << "the relay's second batch did not wait for the gap";
}

// An authoritative snapshot (LM's relay) erases what its sender no longer has, judged by the
// ids it carries: the same objects go from the SLAM map and from S_full. Here the sender has
// a keyframe (200) made after the last point (129), and no longer that point: it knew of the
// point, so the point goes from both.
TEST_F(EpochLabels, AnAuthoritativeSnapshotErasesTheSameObjectsFromTheMapAndFromSFull) {
  constexpr Id kErased = 100 + kPoints - 1, kNewer = 200;
  ASSERT_TRUE(pointHere(kErased));
  ASSERT_TRUE(observer_.hasPoint(kErased));
  integrator_.applyGlobal({snapshotWithoutLastPoint(kNewer)}, true);
  EXPECT_FALSE(observer_.hasPoint(kErased));
  EXPECT_FALSE(pointHere(kErased)) << "erased from S_full but left in the SLAM map";
  EXPECT_TRUE(pointHere(100));
}

// The same snapshot without the last point, but with nothing newer of the point's node: the
// sender may not have heard of the point yet, and it stays. Once that node has left, nothing of
// it is on the way any more, and the point goes. (A mapping node that died left a point at LC
// that TR, the gateway after it, never got: LC ended one point more than TR.)
TEST_F(EpochLabels, AnAuthoritativeSnapshotErasesThePointsOfANodeThatLeftThatItsSenderNeverGot) {
  constexpr Id kOrphan = 100 + kPoints - 1;
  MapRecord g;
  g.kind = MapRecord::Kind::Global;
  g.map = kMap;
  g.epoch = 1;
  g.keyframes.push_back(keyframeRecord(kFirst, poseAt(0.0)));
  g.keyframes.push_back(keyframeRecord(kSecond, poseAt(0.4)));
  addPoints(g, kPoints - 1);
  ASSERT_TRUE(integrator_.applyGlobal({g}, true));
  EXPECT_TRUE(pointHere(kOrphan)) << "erased though its maker may still send it to the sender";
  EXPECT_TRUE(observer_.hasPoint(kOrphan));
  integrator_.setDeparted([](uint16_t node) { return node == core::IdGenerator::node(kOrphan); });
  ASSERT_TRUE(integrator_.applyGlobal({g}, true));
  EXPECT_FALSE(pointHere(kOrphan)) << "its maker left, and the snapshot's sender never got it";
  EXPECT_FALSE(observer_.hasPoint(kOrphan));
  EXPECT_TRUE(pointHere(100));
}

// The sender took its snapshot with the map's second keyframe still in its queue: it holds
// the first keyframe and the points that keyframe brought, whose ids are newer than the second
// keyframe's (tracking numbers a new map's two keyframes, then its points). Judged by the
// newest id of any kind, the receiver erased the keyframe it had made itself, from its map
// and from S_full; once the sender mapped it, S_full had it again and the map never did
// (CI-like run over a lossy link: TR one keyframe short of LM and LC). A keyframe
// is known to the sender only if the snapshot holds a newer keyframe of its node.
TEST_F(EpochLabels, AnAuthoritativeSnapshotTakenBeforeTheSenderMappedAKeyframeLeavesThatKeyframe) {
  MapRecord g;
  g.kind = MapRecord::Kind::Global;
  g.map = kMap;
  g.epoch = 1;
  g.keyframes.push_back(keyframeRecord(kFirst, poseAt(0.0)));
  addPoints(g, kPoints);
  ASSERT_TRUE(integrator_.applyGlobal({g}, true));
  EXPECT_EQ(observer_.digest().keyframes.count(kSecond), 1u) << "left S_full";
  auto map = slam_.findMap(kMap);
  std::lock_guard lock(map->mutex);
  EXPECT_EQ(map->keyframes.count(kSecond), 1u) << "left the SLAM map";
  EXPECT_EQ(map->points.size(), static_cast<size_t>(kPoints));
}

// LC merged or corrected the map and has not published the update yet; the relay of its
// previous update comes in, labelled with the epoch LC last published. That relay is older
// than LC's map: taken as authoritative, it erased what the correction brought in (a merged
// map's keyframes, at LC and then at every node; CI). It is taken as a stale
// local map instead, and the caller told so.
TEST_F(EpochLabels, AnAuthoritativeSnapshotOlderThanACorrectionMadeHereErasesNothing) {
  constexpr Id kUnknownToSender = 100 + kPoints - 1, kNewer = 200;
  correct(core::Sim3(Eigen::Quaterniond::Identity(), {0.1, 0, 0}, 1.0), 1);  // published as 1
  {
    auto map = slam_.findMap(kMap);
    std::lock_guard lock(map->mutex);
    ++map->epoch;  // a correction made here, its label not noted yet
  }
  EXPECT_FALSE(integrator_.applyGlobal({snapshotWithoutLastPoint(kNewer)}, true));
  EXPECT_TRUE(pointHere(kUnknownToSender));
  EXPECT_TRUE(observer_.hasPoint(kUnknownToSender));
  EXPECT_LT((*pointHere(100) - (pointAt(0) + Eigen::Vector3d(0.1, 0, 0))).norm(), 1e-9) << "poses of the old frame taken";
}

// Two maps that have not merged (tracking lost the first and began a second): a snapshot of
// one says nothing about the other. Its sender's newest ids are newer than everything of the
// other map, so judged by ids alone S_full would lose the other map, here and at every node
// that took the relay.
TEST_F(EpochLabels, AnAuthoritativeSnapshotOfOneMapLeavesAnotherMapsRecords) {
  constexpr Id kOtherMap = 8, kOtherKeyframe = 20, kOtherPoint = 150, kNewer = 200;
  KeyFrameMessage other;
  other.keyframe.id = kOtherKeyframe;
  other.keyframe.map = kOtherMap;
  other.keyframe.full = true;
  other.keyframe.frame = featureFrame(2);
  other.keyframe.T_cw = poseAt(2.0);
  PointRecord p;
  p.id = kOtherPoint;
  p.position = pointAt(3);
  p.full = true;
  p.first_keyframe = kOtherKeyframe;
  other.points.push_back(p);
  other.keyframe.matches.emplace_back(0, kOtherPoint);
  ASSERT_TRUE(integrator_.addKeyframe(other, 0).keyframe);
  ASSERT_TRUE(observer_.hasPoint(kOtherPoint));
  ASSERT_EQ(observer_.keyframeCount(), 3u);

  MapRecord g = snapshotWithoutLastPoint(kNewer);
  integrator_.applyGlobal({g}, true);
  EXPECT_FALSE(observer_.hasPoint(100 + kPoints - 1)) << "the snapshot's own map is still pruned";
  EXPECT_TRUE(observer_.hasPoint(kOtherPoint)) << "the other map's point left S_full";
  EXPECT_EQ(observer_.digest().keyframes.count(kOtherKeyframe), 1u) << "the other map's keyframe left S_full";

  // Once a snapshot says the other map lives in this one, its records are this map's to judge.
  g.epoch = 2;
  g.merged_maps = {kOtherMap};
  integrator_.applyGlobal({g}, true);
  EXPECT_FALSE(observer_.hasPoint(kOtherPoint));
  EXPECT_EQ(observer_.digest().keyframes.count(kOtherKeyframe), 0u);
}

// At the heal of a partition, LC may take the returning tracking node's map and send an
// update before the gateway has taken it. The gateway holds that update until it has, and
// applies it only if it was made from that map: one that lacks keyframes of the map older than
// its own newest was made from the map as it was before.
TEST(CoversSnapshot, AnUpdateCoversASnapshotOnlyIfItHoldsEverythingOlderThanItsNewest) {
  const auto records = [](std::vector<Id> ids) {
    MapRecord m;
    m.kind = MapRecord::Kind::Global;
    for (Id id : ids) {
      KeyFrameRecord k;
      k.id = id;
      m.keyframes.push_back(k);
    }
    return std::vector<MapRecord>{m};
  };
  const Id a = Id{1} << 48;  // keyframes of node 1
  const Id b = Id{2} << 48;  // of node 2
  const auto snapshot = records({a + 1, a + 2, a + 3, a + 4, b + 1});
  EXPECT_TRUE(StateIntegrator::covers(records({a + 1, a + 2, a + 3, a + 4, b + 1}), snapshot));
  EXPECT_TRUE(StateIntegrator::covers(records({a + 1, a + 2, a + 3, b + 1}), snapshot)) << "a + 4 is newer than it knew";
  EXPECT_TRUE(StateIntegrator::covers(records({a + 1, a + 2, a + 3, a + 4, a + 5, b + 1}), snapshot));
  EXPECT_FALSE(StateIntegrator::covers(records({a + 1, a + 4, b + 1}), snapshot)) << "made before a + 2 and a + 3 were in";
  EXPECT_FALSE(StateIntegrator::covers(records({a + 1, a + 2, a + 3, a + 4, b + 2}), snapshot)) << "b + 1 missing";
}

}  // namespace
}  // namespace hiveslam::distribution
