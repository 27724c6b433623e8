// DdsTransport's life cycle: what a node does while its transport is not up must not touch
// Fast DDS entities that are not there (or are being deleted).
#include "communication/dds/dds_transport.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <atomic>
#include <condition_variable>
#include <mutex>
#include <thread>
#include <vector>

#include "eventually.hpp"

namespace hiveslam::communication {
namespace {

// A peer event handled while the node stops re-plans its tasks and subscribes: that reader once
// went into a subscriber being deleted (a TR that never finished). Before start()
// there is no subscriber at all (it crashed).
TEST(DdsTransport, SubscribingBeforeStartOrWhileStoppingIsIgnored) {
  DdsTransport transport({232});  // node tests use 1-229, reader_gate_test 230-231 (232 is the last)
  transport.subscribe(Topic::LmMap, [](Message&&) {});
  PeerInfo self;
  self.node = 9;
  transport.start(self, [](const PeerInfo&, bool) {});
  std::atomic<bool> stopped{false};
  std::thread peer_events([&] {
    while (!stopped)
      for (int t = 0; t < kTopicCount; ++t) transport.subscribe(static_cast<Topic>(t), [](Message&&) {});
  });
  std::this_thread::sleep_for(std::chrono::milliseconds(50));
  transport.stop();
  stopped = true;
  peer_events.join();
  transport.subscribe(Topic::LcMap, [](Message&&) {});
  EXPECT_FALSE(transport.peerReads(Topic::LmMap, 1));
}

// A node's announcement carries the peers it has heard (what a tracking node waits for before
// its first frame, distribution/distributed_node.hpp: mutualTasks).
TEST(DdsTransport, AnAnnouncementCarriesThePeersTheNodeHasHeard) {
  // The domain of the test above (Fast DDS has none above 232): its node 9 is ignored here.
  DdsTransport a({232}), b({232});
  PeerInfo self_a, self_b;
  self_a.node = 1;
  self_b.node = 2;
  self_b.seen = {1, 7};
  std::mutex mutex;
  std::condition_variable heard;
  std::vector<uint16_t> seen_by_b;
  bool b_present = false;
  a.start(self_a, [&](const PeerInfo& p, bool present) {
    std::lock_guard lock(mutex);
    if (p.node != 2) return;
    b_present = present;
    seen_by_b = p.seen;
    heard.notify_all();
  });
  b.start(self_b, [](const PeerInfo&, bool) {});
  std::unique_lock lock(mutex);
  ASSERT_TRUE(heard.wait_for(lock, std::chrono::seconds(10), [&] { return b_present; }));
  EXPECT_EQ(seen_by_b, (std::vector<uint16_t>{1, 7}));
  // A change of what it has heard is news, not a repeat.
  self_b.seen = {1};
  lock.unlock();
  b.announce(self_b);
  lock.lock();
  EXPECT_TRUE(heard.wait_for(lock, std::chrono::seconds(10), [&] { return seen_by_b == std::vector<uint16_t>{1}; }));
  lock.unlock();
  b.stop();
  a.stop();
}

// The packet writers keep what they wrote (transient-local, see dds_transport.cpp), yet a
// reader that matches later gets only what is written after it matched, as with volatile
// writers: a node that joins learns the maps from a snapshot, never from old packets.
TEST(DdsTransport, AReaderThatMatchesLateGetsOnlyWhatIsWrittenAfter) {
  DdsTransport a({232}), b({232});
  PeerInfo self_a, self_b;
  self_a.node = 1;
  self_b.node = 2;
  a.start(self_a, [](const PeerInfo&, bool) {});
  const auto packet = [](uint64_t seq) {
    Message m;
    m.source = 1;
    m.seq = seq;
    m.body.assign(3000, static_cast<uint8_t>(seq));  // fragmented: over one datagram
    return m;
  };
  for (uint64_t seq = 1; seq <= 3; ++seq) a.publish(Topic::LmMap, packet(seq));
  std::mutex mutex;
  std::condition_variable got;
  std::vector<uint64_t> received;
  b.start(self_b, [](const PeerInfo&, bool) {});
  b.subscribe(Topic::LmMap, [&](Message&& m) {
    std::lock_guard lock(mutex);
    received.push_back(m.seq);
    got.notify_all();
  });
  ASSERT_TRUE(testing::eventually([&] { return a.peerReads(Topic::LmMap, 2); }, std::chrono::seconds(10)));
  a.publish(Topic::LmMap, packet(4));
  std::unique_lock lock(mutex);
  ASSERT_TRUE(got.wait_for(lock, std::chrono::seconds(10), [&] { return !received.empty(); }));
  // Anything older would have come first.
  got.wait_for(lock, std::chrono::milliseconds(300));
  EXPECT_EQ(received, (std::vector<uint64_t>{4}));
  lock.unlock();
  b.stop();
  a.stop();
}

// A teardown that hangs inside Fast DDS (2.9 has lock-order deadlocks there: a TR once never
// ended its run) is left behind once its flush time and margin are over: stop() returns, the
// node's calls after it return at once, and the program knows to end without Fast DDS's exit
// handlers (apps/main.cpp).
TEST(DdsTransport, AStopThatHangsInsideFastDdsIsLeftBehind) {
  std::mutex mutex;
  std::condition_variable released;
  bool release = false;
  DdsOptions options;
  options.domain = 232;
  options.leave_flush_ms = 100;
  options.teardown_margin_ms = 200;
  options.teardown_hook = [&] {
    std::unique_lock lock(mutex);
    released.wait(lock, [&] { return release; });
  };
  DdsTransport transport(options);
  PeerInfo self;
  self.node = 5;
  transport.start(self, [](const PeerInfo&, bool) {});
  const auto start = std::chrono::steady_clock::now();
  transport.stop();
  const auto stopped = std::chrono::steady_clock::now();
  EXPECT_LT(stopped - start, std::chrono::seconds(5));
  EXPECT_GE(stopped - start, std::chrono::milliseconds(300));
  EXPECT_EQ(DdsTransport::teardownsRunning(), 1);
  transport.publish(Topic::LmMap, Message{});
  transport.subscribe(Topic::LcMap, [](Message&&) {});
  transport.unsubscribe(Topic::LcMap);
  EXPECT_FALSE(transport.peerReads(Topic::LmMap, 1));
  transport.stop();  // idempotent
  EXPECT_LT(std::chrono::steady_clock::now() - stopped, std::chrono::seconds(1));
  {
    std::lock_guard lock(mutex);
    release = true;
  }
  released.notify_all();
  EXPECT_TRUE(testing::eventually([] { return DdsTransport::teardownsRunning() == 0; }, std::chrono::seconds(10)));
}

}  // namespace
}  // namespace hiveslam::communication
