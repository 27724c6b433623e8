#pragma once
// The KeyFrame Publisher: new keyframes out, on its own thread, first in first out. A keyframe
// is captured under its map's lock only when its turn comes (tracking never waits for the
// encoding), with full records of the points the receivers do not know yet and, for a new map,
// the map's first keyframe.
#include <deque>
#include <functional>
#include <memory>
#include <thread>

#include "common/blocking_queue.hpp"
#include "communication/transport.hpp"
#include "core/map/map.hpp"
#include "distribution/observer.hpp"
#include "distribution/sent_ledger.hpp"

namespace hiveslam::distribution {

class KeyframePublisher {
 public:
  struct Job {
    std::shared_ptr<core::Map> map;
    std::shared_ptr<core::KeyFrame> keyframe;
    communication::Topic topic = communication::Topic::TrKeyframes;
    uint8_t target = 0;  // 1 LM, 2 LC; for a control packet (no keyframe) the command
    // No packet: the map went to a newcomer in a snapshot, so its next keyframe goes without
    // the map's earlier keyframes as companions.
    bool handed_over = false;
    // A packet made elsewhere (observations measured again), sent in its turn as it is.
    std::shared_ptr<const communication::Message> packet = nullptr;
  };
  // known(point): the receivers of `topic` already have the point.
  using Known = std::function<bool(communication::Topic, core::Id)>;
  // label(map), with the map's mutex held: the global epoch of the map's current frame. A
  // keyframe goes out labelled with it (StateIntegrator).
  using Label = std::function<uint64_t(const core::Map&)>;
  // await_readers(topic): returns once the peers that joined lately read `topic` (ReaderGate);
  // a packet published before a peer's reader has matched never reaches that peer.
  using AwaitReaders = std::function<void(communication::Topic)>;
  KeyframePublisher(communication::Transport& transport, Observer& observer, SentLedger& ledger, uint16_t node,
                    Known known, Label label, AwaitReaders await_readers = {});
  ~KeyframePublisher();
  void push(Job job) { queue_.push(std::move(job)); }
  // Sends what is queued, then stops the thread.
  void finish();
  int published() const { return published_; }

 private:
  void loop();
  void publish(const Job& job);
  communication::Transport& transport_;
  Observer& observer_;
  SentLedger& ledger_;
  uint16_t node_;
  Known known_;
  Label label_;
  AwaitReaders await_readers_;
  BlockingQueue<Job> queue_;
  std::atomic<int> published_{0};
  std::unordered_map<core::Id, bool> maps_started_;  // publisher thread only
  std::unordered_map<core::Id, std::deque<core::Id>> recent_;  // last keyframes sent, per map
  std::thread thread_;
};

}  // namespace hiveslam::distribution
