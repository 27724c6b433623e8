#pragma once
// An in-process network: endpoints that behave like DDS participants on one domain (peers
// discovered on start, gone on stop, packets delivered to subscribed endpoints only, in order
// per publisher and topic) without sockets. Unit tests run several nodes in one process on it.
#include <array>
#include <memory>
#include <mutex>
#include <vector>

#include "communication/transport.hpp"

namespace hiveslam::communication {

class InProcTransport;

class InProcNetwork {
 public:
  // A new endpoint on this network (the network must outlive it).
  std::unique_ptr<InProcTransport> endpoint();
  // Tests: the next `count` packets published on `topic` reach no one, as packets written
  // before a new peer's reader matched never reach it over DDS.
  void loseNext(Topic topic, int count = 1);

 private:
  friend class InProcTransport;
  struct Member;
  void join(const std::shared_ptr<Member>& m);
  void leave(const std::shared_ptr<Member>& m);
  void announce(const std::shared_ptr<Member>& m);
  void deliver(const Member* from, Topic topic, const Message& message);
  bool reads(uint16_t node, Topic topic);
  std::mutex mutex_;
  std::vector<std::shared_ptr<Member>> members_;
  std::array<int, kTopicCount> to_lose_{};
};

class InProcTransport final : public Transport {
 public:
  explicit InProcTransport(InProcNetwork& network);
  ~InProcTransport() override;
  void start(const PeerInfo& self, PeerHandler on_peer) override;
  void announce(const PeerInfo& self) override;
  void publish(Topic topic, Message&& message) override;
  void subscribe(Topic topic, Handler handler) override;
  void unsubscribe(Topic topic) override;
  bool peerReads(Topic topic, uint16_t node) override;
  void stop() override;
  TrafficReport traffic() const override;

 private:
  InProcNetwork& network_;
  std::shared_ptr<InProcNetwork::Member> member_;
};

}  // namespace hiveslam::communication
