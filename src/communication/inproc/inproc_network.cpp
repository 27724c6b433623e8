#include "communication/inproc/inproc_network.hpp"

#include <algorithm>
#include <array>

namespace hiveslam::communication {

// One endpoint as the network sees it. Handlers are shared pointers so that a delivery in
// progress keeps its handler alive through an unsubscribe.
struct InProcNetwork::Member {
  std::mutex mutex;  // guards everything below
  PeerInfo self;
  bool joined = false;
  Transport::PeerHandler on_peer;
  std::array<std::shared_ptr<Transport::Handler>, kTopicCount> handlers;
  TrafficCounter traffic;
};

std::unique_ptr<InProcTransport> InProcNetwork::endpoint() { return std::make_unique<InProcTransport>(*this); }

void InProcNetwork::join(const std::shared_ptr<Member>& m) {
  // Callbacks run after the network lock is released: a peer handler may subscribe.
  std::vector<std::pair<Transport::PeerHandler, PeerInfo>> calls;
  {
    std::lock_guard lock(mutex_);
    for (const auto& other : members_) {
      std::scoped_lock both(other->mutex, m->mutex);
      calls.emplace_back(other->on_peer, m->self);
      calls.emplace_back(m->on_peer, other->self);
    }
    members_.push_back(m);
    std::lock_guard l(m->mutex);
    m->joined = true;
  }
  for (auto& [handler, info] : calls)
    if (handler) handler(info, true);
}

void InProcNetwork::announce(const std::shared_ptr<Member>& m) {
  std::vector<std::pair<Transport::PeerHandler, PeerInfo>> calls;
  {
    std::lock_guard lock(mutex_);
    for (const auto& other : members_) {
      if (other == m) continue;
      std::scoped_lock both(other->mutex, m->mutex);
      calls.emplace_back(other->on_peer, m->self);
    }
  }
  for (auto& [handler, info] : calls)
    if (handler) handler(info, true);
}

void InProcNetwork::leave(const std::shared_ptr<Member>& m) {
  std::vector<std::pair<Transport::PeerHandler, PeerInfo>> calls;
  {
    std::lock_guard lock(mutex_);
    auto it = std::find(members_.begin(), members_.end(), m);
    if (it == members_.end()) return;
    members_.erase(it);
    std::lock_guard l(m->mutex);
    m->joined = false;
    for (const auto& other : members_) {
      std::lock_guard lo(other->mutex);
      calls.emplace_back(other->on_peer, m->self);
    }
  }
  for (auto& [handler, info] : calls)
    if (handler) handler(info, false);
}

void InProcNetwork::loseNext(Topic topic, int count) {
  std::lock_guard lock(mutex_);
  to_lose_[static_cast<size_t>(topic)] += count;
}

void InProcNetwork::deliver(const Member* from, Topic topic, const Message& message) {
  std::vector<std::pair<std::shared_ptr<Transport::Handler>, Member*>> targets;
  {
    std::lock_guard lock(mutex_);
    if (int& lose = to_lose_[static_cast<size_t>(topic)]; lose > 0) {
      --lose;
      return;
    }
    for (const auto& m : members_) {
      if (m.get() == from) continue;
      std::lock_guard l(m->mutex);
      if (auto h = m->handlers[static_cast<size_t>(topic)]) targets.emplace_back(std::move(h), m.get());
    }
  }
  for (auto& [handler, member] : targets) {
    member->traffic.received(topic, message.wireSize());
    Message copy = message;
    (*handler)(std::move(copy));
  }
}

bool InProcNetwork::reads(uint16_t node, Topic topic) {
  std::lock_guard lock(mutex_);
  for (const auto& m : members_) {
    std::lock_guard l(m->mutex);
    if (m->self.node == node && m->handlers[static_cast<size_t>(topic)]) return true;
  }
  return false;
}

InProcTransport::InProcTransport(InProcNetwork& network)
    : network_(network), member_(std::make_shared<InProcNetwork::Member>()) {}

InProcTransport::~InProcTransport() { stop(); }

void InProcTransport::start(const PeerInfo& self, PeerHandler on_peer) {
  {
    std::lock_guard lock(member_->mutex);
    member_->self = self;
    member_->on_peer = std::move(on_peer);
  }
  network_.join(member_);
}

void InProcTransport::announce(const PeerInfo& self) {
  {
    std::lock_guard lock(member_->mutex);
    member_->self = self;
  }
  network_.announce(member_);
}

void InProcTransport::publish(Topic topic, Message&& message) {
  {
    std::lock_guard lock(member_->mutex);
    if (!member_->joined) return;
  }
  member_->traffic.sent(topic, message.wireSize());
  network_.deliver(member_.get(), topic, message);
}

void InProcTransport::subscribe(Topic topic, Handler handler) {
  std::lock_guard lock(member_->mutex);
  if (!member_->joined) return;  // not started, or stopped (as DdsTransport)
  member_->handlers[static_cast<size_t>(topic)] = std::make_shared<Handler>(std::move(handler));
}

void InProcTransport::unsubscribe(Topic topic) {
  std::lock_guard lock(member_->mutex);
  member_->handlers[static_cast<size_t>(topic)].reset();
}

// A peer subscribes from its own thread after joining; DDS matching has the same gap.
bool InProcTransport::peerReads(Topic topic, uint16_t node) { return network_.reads(node, topic); }

void InProcTransport::stop() {
  network_.leave(member_);
  std::lock_guard lock(member_->mutex);
  member_->handlers = {};
}

TrafficReport InProcTransport::traffic() const { return member_->traffic.report(); }

}  // namespace hiveslam::communication
