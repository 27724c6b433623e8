// A tracking node (and a loop-closing node) and its peers, with the peer events scripted.
//
// Mutual discovery: a tracking node counts a peer as there for it only once the peer has heard
// it too (PeerInfo::seen) and, for a mapping peer, reads its keyframes. Discovery is one-sided:
// over a lossy link a mapping node heard TR 2.9 s after TR had heard it, and the keyframes TR
// sent meanwhile reached nobody (TR's first map lost in 3 of 24 runs).
//
// End of run: the Done comes from the gateway; a gateway that leaves first sends none, and TR
// must not wait out its whole timeout for it (over a slow link it waited 120 s).
// With an LC left, TR finishes the exchange with it as the new gateway; an LC that has answered
// and is left alone ends too (it waited for the Done until killed).
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <future>
#include <mutex>
#include <thread>

#include "core/camera/pinhole_radtan.hpp"
#include "core/system/slam_system.hpp"
#include "distribution/distributed_node.hpp"
#include "distribution/packet.hpp"
#include "eventually.hpp"

namespace hiveslam::distribution {
namespace {

using communication::PeerInfo;
using communication::Task;
using communication::taskBit;
using communication::Topic;

using hiveslam::testing::eventually;  // a departure, say, is handled on the map handler's thread

// A transport whose peer events the test makes, and whose mapping peer's keyframe reader
// matches when the test says so. It keeps the node's last announcement.
class ScriptedTransport final : public communication::Transport {
 public:
  std::atomic<bool> lm_reads{false};
  void start(const PeerInfo& self, PeerHandler on_peer) override {
    std::lock_guard lock(mutex_);
    announced_ = self;
    on_peer_ = std::move(on_peer);
  }
  void announce(const PeerInfo& self) override {
    std::lock_guard lock(mutex_);
    announced_ = self;
  }
  void publish(Topic topic, communication::Message&& m) override {
    if (m.kind != static_cast<uint8_t>(PacketKind::Control)) return;
    std::lock_guard lock(mutex_);
    controls_.push_back({topic, static_cast<Control>(m.target)});
  }
  void subscribe(Topic topic, Handler handler) override {
    std::lock_guard lock(mutex_);
    handlers_[static_cast<size_t>(topic)] = std::move(handler);
  }
  void unsubscribe(Topic) override {}
  bool peerReads(Topic topic, uint16_t node) override {
    return (node == 2 && topic == Topic::TrKeyframes && lm_reads) || (node == 3 && topic == Topic::LmKeyframes) ||
           topic == Topic::LcMap;
  }
  void stop() override {}
  communication::TrafficReport traffic() const override { return {}; }

  void peer(const PeerInfo& p, bool present) { on_peer_(p, present); }
  // A packet from a peer, as the transport's reader thread hands it on.
  void deliver(Topic topic, communication::Message m) {
    Handler h;
    {
      std::lock_guard lock(mutex_);
      h = handlers_[static_cast<size_t>(topic)];
    }
    ASSERT_TRUE(h) << "the node does not read " << communication::topicName(topic);
    h(std::move(m));
  }
  std::vector<uint16_t> announcedSeen() {
    std::lock_guard lock(mutex_);
    return announced_.seen;
  }
  // Waits until the node has published `count` control packets `c` on `topic`.
  bool published(Topic topic, Control c, int count = 1, std::chrono::seconds within = std::chrono::seconds(30)) {
    return eventually(
        [&] {
          std::lock_guard lock(mutex_);
          return std::count(controls_.begin(), controls_.end(), std::pair{topic, c}) >= count;
        },
        within);
  }

 private:
  std::mutex mutex_;
  std::vector<std::pair<Topic, Control>> controls_;
  PeerInfo announced_;
  PeerHandler on_peer_;
  std::array<Handler, communication::kTopicCount> handlers_;
};

PeerInfo peerInfo(uint16_t node, Task task, std::vector<uint16_t> seen) {
  PeerInfo p;
  p.node = node;
  p.name = communication::taskName(task);
  p.task = task;
  p.incarnation = 100 + node;
  p.seen = std::move(seen);
  return p;
}

// A node with no frames, on a scripted transport: TR (id 1) by default, or LC (id 3), which
// has no camera, as `hiveslam node --task lc` has none.
struct TrackingNode {
  explicit TrackingNode(Task task = Task::Tracking)
      : slam{core::SlamSettings{}, task == Task::Tracking ? camera : nullptr, core::SlamSystem::Mode::Offline, nullptr,
             task == Task::Tracking ? uint16_t{1} : uint16_t{3}},
        node{slam, transport, {task, task == Task::Tracking ? uint16_t{1} : uint16_t{3}, communication::taskName(task), {}}} {
    node.start();
  }
  ~TrackingNode() {
    node.stop();
    slam.finish();
  }
  std::shared_ptr<camera::PinholeRadTan> camera =
      std::make_shared<camera::PinholeRadTan>(752, 480, 458.0, 457.0, 367.0, 248.0);
  core::SlamSystem slam;
  ScriptedTransport transport;
  DistributedNode node;
};

// TR with an LM that reads its keyframes and an LC, each having heard the other two.
void offloadToLmAndLc(TrackingNode& tr) {
  tr.transport.lm_reads = true;
  tr.transport.peer(peerInfo(3, Task::LoopClosing, {1, 2}), true);
  tr.transport.peer(peerInfo(2, Task::Mapping, {1, 3}), true);
}

TEST(MutualDiscovery, ATrackingNodeWaitsForPeersThatHaveHeardItAndAMappingPeerThatReadsItsKeyframes) {
  TrackingNode tr;
  auto& transport = tr.transport;
  auto& node = tr.node;
  EXPECT_TRUE(transport.announcedSeen().empty());

  // TR hears LM, which has not heard TR yet.
  transport.peer(peerInfo(2, Task::Mapping, {}), true);
  EXPECT_EQ(node.presentTasks(), taskBit(Task::Mapping));
  EXPECT_EQ(node.mutualTasks(), 0);
  EXPECT_EQ(transport.announcedSeen(), std::vector<uint16_t>{2}) << "TR must tell LM it hears it";

  // LM has heard TR, but its reader of TR's keyframes has not matched.
  transport.peer(peerInfo(2, Task::Mapping, {1}), true);
  EXPECT_EQ(node.mutualTasks(), 0);
  transport.lm_reads = true;
  EXPECT_EQ(node.mutualTasks(), taskBit(Task::Mapping));

  // LC reads nothing from TR: having heard it is enough.
  transport.peer(peerInfo(3, Task::LoopClosing, {2}), true);
  EXPECT_EQ(node.mutualTasks(), taskBit(Task::Mapping));
  transport.peer(peerInfo(3, Task::LoopClosing, {1, 2}), true);
  EXPECT_EQ(node.mutualTasks(), taskBit(Task::Mapping) | taskBit(Task::LoopClosing));
  EXPECT_EQ(transport.announcedSeen(), (std::vector<uint16_t>{2, 3}));

  // A peer that leaves is neither present nor heard any more.
  transport.peer(peerInfo(2, Task::Mapping, {1, 3}), false);
  EXPECT_TRUE(eventually([&] { return node.mutualTasks() == taskBit(Task::LoopClosing); }));
  EXPECT_TRUE(eventually([&] { return transport.announcedSeen() == std::vector<uint16_t>{3}; }));
}

TEST(EndOfRun, ATrackingNodeStopsWaitingForTheDoneWhenItsGatewayLeaves) {
  TrackingNode tr;
  tr.transport.lm_reads = true;
  tr.transport.peer(peerInfo(2, Task::Mapping, {1}), true);
  ASSERT_TRUE(tr.node.plan().keyframes_to_lm);
  auto finished = std::async(std::launch::async, [&] { return tr.node.finishRun(std::chrono::minutes(10)); });
  EXPECT_EQ(finished.wait_for(std::chrono::milliseconds(300)), std::future_status::timeout) << "no Done came yet";
  tr.transport.peer(peerInfo(2, Task::Mapping, {1}), false);
  ASSERT_EQ(finished.wait_for(std::chrono::minutes(1)), std::future_status::ready) << "still waiting for a gone gateway";
  EXPECT_FALSE(finished.get()) << "no Done came: the exchange did not complete";
  EXPECT_TRUE(tr.node.plan().mapping) << "alone again, TR maps";
}

// The gateway's Done, then its leaving notice, which comes on its own path: the Done still
// counts though it waits here behind the gateway's earlier map packets (the last snapshot of a
// real run; here 3000 empty ones). Judged at the notice, the run ended "incomplete" with the
// Done in the queue, on a run that had completed. And a gateway that leaves after its Done has
// finished, not died: TR does not take mapping back (it did, and a bench run's TR then sent LC
// its whole map, past LC's own end, and waited 10 s for its readers).
TEST(EndOfRun, ADoneSentBeforeTheGatewayLeftCountsThoughTheNoticeCameFirst) {
  TrackingNode tr;
  tr.transport.lm_reads = true;
  tr.transport.peer(peerInfo(2, Task::Mapping, {1}), true);
  auto finished = std::async(std::launch::async, [&] { return tr.node.finishRun(std::chrono::minutes(10)); });
  MapRecord empty;
  empty.map = 12345;
  for (int i = 0; i < 3000; ++i) tr.transport.deliver(Topic::LmMap, pack(empty, 2, 0, empty.map, 0));
  tr.transport.deliver(Topic::LmMap, controlPacket(2, Control::Done));
  tr.transport.peer(peerInfo(2, Task::Mapping, {1}), false);
  ASSERT_EQ(finished.wait_for(std::chrono::minutes(1)), std::future_status::ready);
  EXPECT_TRUE(finished.get());
  ASSERT_TRUE(eventually([&] { return tr.node.presentTasks() == 0; })) << "LM's departure never handled";
  EXPECT_FALSE(tr.node.plan().mapping) << "TR took mapping back from a gateway that had finished";
}

// LM leaves after TR's EndOfSequence, before its Done; LC stays. TR, mapping again, asks LC
// for its Done as the new gateway and ends with the exchange completed.
TEST(EndOfRun, ATrackingNodeWhoseGatewayLeftFinishesTheRunWithTheLoopClosingNode) {
  TrackingNode tr;
  offloadToLmAndLc(tr);
  ASSERT_TRUE(tr.node.plan().keyframes_to_lm);
  auto finished = std::async(std::launch::async, [&] { return tr.node.finishRun(std::chrono::minutes(10)); });
  ASSERT_TRUE(tr.transport.published(Topic::TrKeyframes, Control::EndOfSequence));
  tr.transport.peer(peerInfo(2, Task::Mapping, {1, 3}), false);
  ASSERT_TRUE(tr.transport.published(Topic::LmKeyframes, Control::EndOfSequence)) << "TR did not ask LC to finish";
  EXPECT_TRUE(tr.node.plan().local_maps) << "TR is the gateway now";
  EXPECT_EQ(finished.wait_for(std::chrono::milliseconds(300)), std::future_status::timeout) << "LC has not answered";
  tr.transport.deliver(Topic::LcMap, controlPacket(3, Control::Done));
  ASSERT_EQ(finished.wait_for(std::chrono::minutes(1)), std::future_status::ready);
  EXPECT_TRUE(finished.get());
  EXPECT_TRUE(tr.transport.published(Topic::LmMap, Control::Done)) << "LC gets no Done from its new gateway";
}

// LC has answered LM's EndOfSequence; LM dies before its last snapshot and Done. While TR is
// there LC waits (TR may finish as the gateway); TR asks again, LC answers again; and an LC
// left alone ends without the Done, saying so.
TEST(EndOfRun, ALoopClosingNodeAnswersEachGatewayAndEndsWhenLeftAlone) {
  TrackingNode lc(Task::LoopClosing);
  lc.transport.peer(peerInfo(1, Task::Tracking, {2, 3}), true);
  lc.transport.peer(peerInfo(2, Task::Mapping, {1, 3}), true);
  lc.transport.deliver(Topic::LmKeyframes, controlPacket(2, Control::EndOfSequence));
  ASSERT_TRUE(lc.transport.published(Topic::LcMap, Control::Done));
  lc.transport.peer(peerInfo(2, Task::Mapping, {1, 3}), false);
  EXPECT_FALSE(lc.node.waitUntilDone(std::chrono::milliseconds(300))) << "TR is still there";

  lc.transport.deliver(Topic::LmKeyframes, controlPacket(1, Control::EndOfSequence));
  ASSERT_TRUE(lc.transport.published(Topic::LcMap, Control::Done, 2)) << "no Done for the new gateway";
  EXPECT_FALSE(lc.node.waitUntilDone(std::chrono::milliseconds(300)));
  lc.transport.peer(peerInfo(1, Task::Tracking, {3}), false);
  EXPECT_TRUE(lc.node.waitUntilDone(std::chrono::seconds(30))) << "alone, and still waiting for a Done";
  EXPECT_FALSE(lc.node.completed());
}

TEST(EndOfRun, ALoopClosingNodeThatGotTheDoneHasCompleted) {
  TrackingNode lc(Task::LoopClosing);
  lc.transport.peer(peerInfo(2, Task::Mapping, {3}), true);
  lc.transport.deliver(Topic::LmKeyframes, controlPacket(2, Control::EndOfSequence));
  ASSERT_TRUE(lc.transport.published(Topic::LcMap, Control::Done));
  lc.transport.deliver(Topic::LmMap, controlPacket(2, Control::Done));
  lc.transport.peer(peerInfo(2, Task::Mapping, {3}), false);
  EXPECT_TRUE(lc.node.waitUntilDone(std::chrono::seconds(30)));
  EXPECT_TRUE(lc.node.completed());
}

TEST(KeyframeAcks, TheReportSummarizesTheRoundTripsByRank) {
  std::vector<double> ms;
  for (int i = 100; i >= 1; --i) ms.push_back(i);  // 1..100 ms, in any order
  const auto j = DistributedNode::ackSummary(ms);
  EXPECT_EQ(j["count"], 100);
  EXPECT_DOUBLE_EQ(j["median"].get<double>(), 51.0);
  EXPECT_DOUBLE_EQ(j["p95"].get<double>(), 96.0);
  EXPECT_DOUBLE_EQ(j["max"].get<double>(), 100.0);
  EXPECT_DOUBLE_EQ(DistributedNode::ackSummary({7.0})["p95"].get<double>(), 7.0);
}

// Slow: acknowledgements in a row each later than the limit, or none at all for as many
// times the limit (and longer than a dead gateway's lease). One prompt answer clears the count.
TEST(SlowLink, AGatewayIsTooSlowAfterLateAcknowledgementsInARowOrALongSilence) {
  using namespace std::chrono_literals;
  const GatewayWatch::Clock::time_point t0{};
  GatewayWatch w(1s, 3, 2500ms);
  EXPECT_FALSE(w.tooSlow(t0 + 100s)) << "nothing sent, nothing waits";
  w.sent(t0);
  w.answered(4s);
  w.answered(5s);
  w.answered(50ms);  // a prompt one: the run is broken
  w.answered(4s);
  w.answered(4s);
  EXPECT_FALSE(w.tooSlow(t0 + 20s));
  w.answered(1500ms);
  EXPECT_TRUE(w.tooSlow(t0 + 20s)) << "acknowledgements prove the gateway alive: no lease to wait out";
  EXPECT_EQ(w.slowInARow(), 3);

  GatewayWatch quiet(1s, 3, 2500ms);
  quiet.sent(t0);
  quiet.sent(t0 + 2s);  // still waiting since the first
  EXPECT_FALSE(quiet.tooSlow(t0 + 3s));
  EXPECT_TRUE(quiet.tooSlow(t0 + 3100ms));
  quiet.answered(3100ms);  // one late answer ends the silence, and is one late answer
  EXPECT_FALSE(quiet.tooSlow(t0 + 20s));
  GatewayWatch leased(1s, 3, 5s);
  leased.sent(t0);
  EXPECT_FALSE(leased.tooSlow(t0 + 4s)) << "a dead gateway may still look present";
  EXPECT_TRUE(leased.tooSlow(t0 + 5100ms));
  // At a loss: a keyframe unanswered for longer than the limit and the lease, and recent.
  EXPECT_FALSE(quiet.starved(t0 + 10s, t0 + 8s)) << "within a dead gateway's lease";
  EXPECT_TRUE(quiet.starved(t0 + 10s, t0 + 7s));
  EXPECT_FALSE(quiet.starved(t0 + 30s, t0)) << "dropped long ago (its map merged), not a slow link";
  GatewayWatch off(0s, 3, 2500ms);
  off.sent(t0);
  EXPECT_FALSE(off.tooSlow(t0 + 100s)) << "0: never";
  EXPECT_FALSE(off.starved(t0 + 3s, t0));
}

// TR gives up offloading: every peer gets a Release, and TR runs the whole system alone. The
// released nodes' announcements, until they leave, change nothing; a restarted one is a
// newcomer again.
TEST(SlowLink, ATrackingNodeReleasesItsPeersAndRunsAlone) {
  TrackingNode tr;
  offloadToLmAndLc(tr);
  ASSERT_TRUE(tr.node.plan().keyframes_to_lm);
  tr.node.releasePeers("a test");
  EXPECT_TRUE(tr.transport.published(Topic::TrKeyframes, Control::Release)) << "LM was not told";
  EXPECT_TRUE(tr.transport.published(Topic::LmMap, Control::Release)) << "LC was not told";
  const auto alone = [&] {
    const Plan p = tr.node.plan();
    return p.mapping && p.loop_closing && !p.keyframes_to_lm && !p.keyframes_to_lc && tr.node.presentTasks() == 0;
  };
  EXPECT_TRUE(alone());
  tr.transport.peer(peerInfo(2, Task::Mapping, {1, 3}), true);  // announced again before leaving
  EXPECT_TRUE(alone()) << "a released node came back without restarting";
  tr.transport.peer(peerInfo(2, Task::Mapping, {1, 3}), false);
  tr.transport.peer(peerInfo(3, Task::LoopClosing, {1, 2}), false);
  EXPECT_TRUE(alone());
  PeerInfo restarted = peerInfo(2, Task::Mapping, {1});
  ++restarted.incarnation;
  tr.transport.peer(restarted, true);
  EXPECT_TRUE(tr.node.plan().keyframes_to_lm) << "a restarted mapping node is a newcomer";
  tr.transport.peer(restarted, false);
  ASSERT_TRUE(eventually([&] { return alone(); })) << "the restarted node's departure never handled";
  auto finished = std::async(std::launch::async, [&] { return tr.node.finishRun(std::chrono::minutes(10)); });
  ASSERT_EQ(finished.wait_for(std::chrono::minutes(1)), std::future_status::ready) << "alone, TR waits for nobody";
  EXPECT_TRUE(finished.get());
}

// A released node's run is over: it leaves, its map not the run's.
TEST(SlowLink, AReleasedNodeEndsItsRun) {
  TrackingNode lc(Task::LoopClosing);
  lc.transport.peer(peerInfo(1, Task::Tracking, {3}), true);
  EXPECT_FALSE(lc.node.waitUntilDone(std::chrono::milliseconds(100)));
  lc.transport.deliver(Topic::LmMap, controlPacket(1, Control::Release));
  EXPECT_TRUE(lc.node.waitUntilDone(std::chrono::minutes(1)));
  EXPECT_TRUE(lc.node.released());
  EXPECT_FALSE(lc.node.completed());
}

}  // namespace
}  // namespace hiveslam::distribution
