#pragma once
// The communication layer over Fast DDS 2.9 (the middleware under ROS 2): one participant per
// node on a DDS domain, one writer per published topic, one reader per subscribed topic, and a
// NodeInfo topic for discovery. Packets are RELIABLE with KEEP_LAST histories and asynchronous
// publishing, so a dead or slow reader never blocks publish(); a peer whose lease expires
// (2 s) is reported gone.
#include <memory>

#include "communication/transport.hpp"

namespace hiveslam::communication {

struct DdsOptions {
  int domain = 0;
  int history_depth = 64;  // packets kept per writer for late acknowledgements
  // UDP datagrams no larger than an Ethernet frame's payload: a 64 KB datagram is ~45 IP
  // fragments, and one lost fragment loses all of it (at 2% packet loss, a keyframe message got
  // through whole less than half the time). MTU-sized datagrams are RTPS fragments that a
  // reader asks for again one by one.
  int max_datagram_bytes = 1400;
  // How often a reliable writer with unacknowledged packets says what it has sent, so that a
  // reader notices a lost last fragment (Fast DDS's default is 3 s).
  int heartbeat_ms = 100;
};

class DdsTransport final : public Transport {
 public:
  explicit DdsTransport(DdsOptions options);
  ~DdsTransport() override;
  void start(const PeerInfo& self, PeerHandler on_peer) override;
  void announce(const PeerInfo& self) override;
  void publish(Topic topic, Message&& message) override;
  void subscribe(Topic topic, Handler handler) override;
  void unsubscribe(Topic topic) override;
  bool peerReads(Topic topic, uint16_t node) override;
  void stop() override;
  TrafficReport traffic() const override;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace hiveslam::communication
