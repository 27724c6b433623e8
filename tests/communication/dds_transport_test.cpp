// DdsTransport's life cycle: what a node does while its transport is not up must not touch
// Fast DDS entities that are not there (or are being deleted).
#include "communication/dds/dds_transport.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <atomic>
#include <thread>

namespace hiveslam::communication {
namespace {

// A peer event handled while the node stops re-plans its tasks and subscribes: that reader once
// went into a subscriber being deleted (a TR that never finished, session 36). Before start()
// there is no subscriber at all (it crashed).
TEST(DdsTransport, SubscribingBeforeStartOrWhileStoppingIsIgnored) {
  DdsTransport transport({232});  // node tests use 1-229, reader_gate_test 230-231
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

}  // namespace
}  // namespace hiveslam::communication
