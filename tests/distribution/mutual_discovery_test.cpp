// Mutual discovery: a tracking node counts a peer as there for it only once the peer has heard
// it too (PeerInfo::seen) and, for a mapping peer, reads its keyframes. Discovery is one-sided:
// over a lossy link a mapping node heard TR 2.9 s after TR had heard it, and the keyframes TR
// sent meanwhile reached nobody (TR's first map lost in 3 of 24 runs, session 39).
#include <gtest/gtest.h>

#include <atomic>
#include <mutex>

#include "core/camera/pinhole_radtan.hpp"
#include "core/system/slam_system.hpp"
#include "distribution/distributed_node.hpp"

namespace hiveslam::distribution {
namespace {

using communication::PeerInfo;
using communication::Task;
using communication::taskBit;
using communication::Topic;

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
  void publish(Topic, communication::Message&&) override {}
  void subscribe(Topic, Handler) override {}
  void unsubscribe(Topic) override {}
  bool peerReads(Topic topic, uint16_t node) override { return node == 2 && topic == Topic::TrKeyframes && lm_reads; }
  void stop() override {}
  communication::TrafficReport traffic() const override { return {}; }

  void peer(const PeerInfo& p, bool present) { on_peer_(p, present); }
  std::vector<uint16_t> announcedSeen() {
    std::lock_guard lock(mutex_);
    return announced_.seen;
  }

 private:
  std::mutex mutex_;
  PeerInfo announced_;
  PeerHandler on_peer_;
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

TEST(MutualDiscovery, ATrackingNodeWaitsForPeersThatHaveHeardItAndAMappingPeerThatReadsItsKeyframes) {
  auto camera = std::make_shared<camera::PinholeRadTan>(752, 480, 458.0, 457.0, 367.0, 248.0);
  core::SlamSystem slam(core::SlamSettings{}, camera, core::SlamSystem::Mode::Offline, nullptr, 1);
  ScriptedTransport transport;
  DistributedNode node(slam, transport, {Task::Tracking, 1, "tr", {}});
  node.start();
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
  EXPECT_EQ(node.mutualTasks(), taskBit(Task::LoopClosing));
  EXPECT_EQ(transport.announcedSeen(), std::vector<uint16_t>{3});
  node.stop();
  slam.finish();
}

}  // namespace
}  // namespace hiveslam::distribution
