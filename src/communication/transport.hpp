#pragma once
// The communication layer's one interface: publish and subscribe typed packets, announce this
// node and hear of peers coming and going. Two implementations: Fast DDS (dds/) and an
// in-process bus (inproc/) with the same behaviour for tests.
//
// A node never receives its own packets, even on a topic it both publishes and reads.
//
// Threads: publish() returns at once (never waits on a slow or dead peer). Handlers run on the
// transport's threads and must only queue the message. Peer events come on a transport thread.
#include <cstdint>
#include <functional>
#include <map>
#include <string>

#include "communication/message.hpp"
#include "communication/traffic_counter.hpp"

namespace hiveslam::communication {

class Transport {
 public:
  using Handler = std::function<void(Message&&)>;
  // present: the peer appeared or changed (tasks, load); false: it left or its lease expired.
  using PeerHandler = std::function<void(const PeerInfo&, bool present)>;

  virtual ~Transport() = default;
  // Joins the network and starts announcing `self`.
  virtual void start(const PeerInfo& self, PeerHandler on_peer) = 0;
  // Announces a change of this node (hosted tasks, load).
  virtual void announce(const PeerInfo& self) = 0;
  virtual void publish(Topic topic, Message&& message) = 0;
  // Only subscribed topics reach this node (and count against its bandwidth). Ignored before
  // start() and once stop() has begun.
  virtual void subscribe(Topic topic, Handler handler) = 0;
  virtual void unsubscribe(Topic topic) = 0;
  // Whether peer `node` reads `topic` from this node now (its reader has matched): what is
  // published before a new peer's reader has matched never reaches that peer. False when the
  // peer is unknown. Does not wait; the caller polls.
  virtual bool peerReads(Topic topic, uint16_t node) = 0;
  // Announces leaving and stops delivering; idempotent.
  virtual void stop() = 0;
  virtual TrafficReport traffic() const = 0;
};

}  // namespace hiveslam::communication
