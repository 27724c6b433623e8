#pragma once
// The communication layer over Fast DDS 2.9 (the middleware under ROS 2): one participant per
// node on a DDS domain, one writer per published topic, one reader per subscribed topic, and a
// NodeInfo topic for discovery. Packets are RELIABLE with KEEP_LAST histories and asynchronous
// publishing, so a dead or slow reader never blocks publish(); a peer whose lease expires
// (2 s) is reported gone. stop() is bounded too (see teardownsRunning()).
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
  // Teardowns that stop() left behind (and still running): Fast DDS deadlocked in one. A
  // program with any must end without Fast DDS's exit handlers, which would wait on it too.
  static int teardownsRunning();

 private:
  struct Impl;
  std::shared_ptr<Impl> impl_;  // shared with a teardown thread that may outlive this object
};

}  // namespace hiveslam::communication
