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

namespace hiveslam::communication {
namespace {

// A peer event handled while the node stops re-plans its tasks and subscribes: that reader once
// went into a subscriber being deleted (a TR that never finished, session 36). Before start()
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

}  // namespace
}  // namespace hiveslam::communication
