#pragma once
// The KeyFrame Subscriber: incoming keyframes, on its own thread, first in first out. Each is
// decoded, put into its map (StateIntegrator) and handed to the module it targets. A malformed
// message is logged and dropped. A keyframe of a map this node does not hold, and that is not
// a new map's (no companions), waits for the map first (AwaitMap): the node took its task over
// and the maps so far are on their way from the node that held them, or the packet that
// started the map was lost and the map must be asked for.
#include <functional>
#include <thread>

#include "common/blocking_queue.hpp"
#include "communication/message.hpp"
#include "distribution/state_integrator.hpp"

namespace hiveslam::distribution {

class KeyframeSubscriber {
 public:
  using Route = std::function<void(const StateIntegrator::Added&, uint8_t target)>;
  using OnControl = std::function<void(const communication::Message&)>;
  // Returns once the map is held here or waiting longer makes no sense. `target`: the
  // module the keyframe is for (which tells whom to ask for the map).
  using AwaitMap = std::function<void(Id map, uint8_t target)>;
  // Observations the sender measured again (end of a run), in order with its keyframes.
  using OnRemeasured = std::function<void(const core::Remeasurements&)>;
  KeyframeSubscriber(StateIntegrator& integrator, Route route, OnControl control, AwaitMap await_map = {},
                     OnRemeasured remeasured = {});
  ~KeyframeSubscriber();
  void push(communication::Message&& m) { queue_.push(std::move(m)); }
  void finish();
  int received() const { return received_; }
  int dropped() const { return dropped_; }
  size_t pending() const { return queue_.size(); }

 private:
  void loop();
  StateIntegrator& integrator_;
  Route route_;
  OnControl control_;
  AwaitMap await_map_;
  OnRemeasured remeasured_;
  BlockingQueue<communication::Message> queue_;
  std::atomic<int> received_{0}, dropped_{0};
  std::thread thread_;
};

}  // namespace hiveslam::distribution
