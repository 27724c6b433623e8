#pragma once
// The communication layer over Fast DDS 2.9 (the middleware under ROS 2): one participant per
// node on a DDS domain, one writer per published topic, one reader per subscribed topic, and a
// NodeInfo topic for discovery. Packets are RELIABLE with KEEP_LAST histories and asynchronous
// publishing, so a dead or slow reader never blocks publish(); a peer whose lease expires
// (2 s) is reported gone.
#include <memory>

#include "communication/dds/dds_options.hpp"
#include "communication/transport.hpp"

namespace hiveslam::communication {

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
