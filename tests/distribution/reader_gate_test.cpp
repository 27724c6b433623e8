// ReaderGate: a keyframe goes out only once the peers that just joined read its topic, so that
// a new map's first keyframe (which carries the map) is not written before their readers match.
#include "distribution/reader_gate.hpp"

#include <gtest/gtest.h>

#include <unistd.h>

#include <atomic>
#include <condition_variable>
#include <mutex>
#include <thread>

#include "communication/dds/dds_transport.hpp"

namespace hiveslam::distribution {
namespace {

using communication::Task;
using communication::Topic;
using namespace std::chrono_literals;

// A transport whose peers' readers match when the test says so; nothing else is used.
class MatchingTransport final : public communication::Transport {
 public:
  std::atomic<bool> lc_reads{false};
  std::atomic<int> asked{0};
  void start(const communication::PeerInfo&, PeerHandler) override {}
  void announce(const communication::PeerInfo&) override {}
  void publish(Topic, communication::Message&&) override {}
  void subscribe(Topic, Handler) override {}
  void unsubscribe(Topic) override {}
  bool peerReads(Topic topic, uint16_t node) override {
    ++asked;
    return node == 3 && topic == Topic::LmKeyframes && lc_reads;
  }
  void stop() override {}
  communication::TrafficReport traffic() const override { return {}; }
};

TEST(ReaderGate, AKeyframeForLoopClosingWaitsForTheReaderOfAnLcThatJustJoined) {
  MatchingTransport transport;
  ReaderGate gate(transport, 1h);
  gate.joined(3, Task::LoopClosing);
  std::atomic<bool> passed{false};
  std::thread publisher([&] {
    gate.await(Topic::LmKeyframes);
    passed = true;
  });
  // Held while the reader has not matched (the gate polls; several polls go by here).
  while (transport.asked < 3) std::this_thread::sleep_for(1ms);
  EXPECT_FALSE(passed);
  transport.lc_reads = true;
  publisher.join();
  EXPECT_TRUE(passed);
  // Matched once, the peer is no newcomer: the next keyframe does not ask again.
  const int before = transport.asked;
  gate.await(Topic::LmKeyframes);
  EXPECT_EQ(transport.asked, before);
}

TEST(ReaderGate, OnlyThePeersThatReadTheTopicAreWaitedFor) {
  MatchingTransport transport;
  ReaderGate gate(transport, 1h);
  gate.joined(3, Task::LoopClosing);  // its reader never matches in this test
  gate.joined(4, Task::Tracking);     // reads no keyframe topic from here
  gate.await(Topic::TrKeyframes);     // keyframes for a mapping node: nobody to wait for
  gate.await(Topic::LmMap);           // map topics are repaired by later snapshots
  SUCCEED();
}

TEST(ReaderGate, APeerThatLeftOrNeverMatchesIsNotWaitedForLong) {
  MatchingTransport transport;
  {
    ReaderGate gate(transport, 1h);
    gate.joined(3, Task::LoopClosing);
    std::thread leaving([&] {
      std::this_thread::sleep_for(20ms);
      gate.left(3);
    });
    gate.await(Topic::LmKeyframes);
    leaving.join();
  }
  {
    ReaderGate gate(transport, 30ms);  // patience runs out
    gate.joined(3, Task::LoopClosing);
    gate.await(Topic::LmKeyframes);
  }
  {
    ReaderGate gate(transport, 1h);
    gate.joined(3, Task::LoopClosing);
    std::thread stopping([&] {
      std::this_thread::sleep_for(20ms);
      gate.stop();  // the node is leaving
    });
    gate.await(Topic::LmKeyframes);
    stopping.join();
  }
  EXPECT_FALSE(transport.lc_reads);
}

// Over Fast DDS: a node that publishes a keyframe the moment it hears of a loop-closing peer
// (as a mapping node does when it forwards a new map) reaches it. DDS announces a peer a little
// before that peer's readers match, and what is written in between goes to no one: a returning
// mapping node forwarded TR's new map to LC that way and LC never got the map (CI).
// Without the gate, and with writers made at their first write, 1 round in 3 lost its packet.
TEST(ReaderGate, OverDdsAKeyframeWrittenAsAPeerJoinsReachesIt) {
  const int domain = 230 + getpid() % 2;  // node tests use 1-229, dds_transport_test 232
  for (int round = 0; round < 5; ++round) {
    communication::DdsTransport mapping({domain}), closing({domain});
    ReaderGate gate(mapping, 10s);
    std::mutex mutex;
    std::condition_variable cv;
    bool joined = false;
    int received = 0;
    communication::PeerInfo self;
    self.node = 2;
    self.task = Task::Mapping;
    self.incarnation = 1;
    mapping.start(self, [&](const communication::PeerInfo& peer, bool present) {
      if (!present || peer.node != 3) return;
      gate.joined(peer.node, peer.task);
      std::lock_guard lock(mutex);
      joined = true;
      cv.notify_all();
    });
    communication::PeerInfo lc;
    lc.node = 3;
    lc.task = Task::LoopClosing;
    lc.incarnation = 1;
    closing.start(lc, [](const communication::PeerInfo&, bool) {});
    closing.subscribe(Topic::LmKeyframes, [&](communication::Message&&) {
      std::lock_guard lock(mutex);
      ++received;
      cv.notify_all();
    });
    {
      std::unique_lock lock(mutex);
      ASSERT_TRUE(cv.wait_for(lock, 10s, [&] { return joined; })) << "round " << round << ": no peer";
    }
    gate.await(Topic::LmKeyframes);
    communication::Message m;
    m.source = 2;
    m.body = {1, 2, 3};
    mapping.publish(Topic::LmKeyframes, std::move(m));
    std::unique_lock lock(mutex);
    EXPECT_TRUE(cv.wait_for(lock, 5s, [&] { return received > 0; })) << "round " << round;
    lock.unlock();
    closing.stop();
    mapping.stop();
  }
}

}  // namespace
}  // namespace hiveslam::distribution
