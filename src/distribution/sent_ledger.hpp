#pragma once
// Which map points each topic has carried in full (descriptor and viewing range): later
// messages on that topic send only their positions. Thread-safe.
#include <Eigen/Core>
#include <array>
#include <mutex>
#include <unordered_map>

#include "communication/message.hpp"
#include "core/map/ids.hpp"

namespace hiveslam::distribution {

class SentLedger {
 public:
  // True when `point` with `observations` observers must go in full on `topic` (and records it).
  bool needsFull(communication::Topic topic, core::Id point, int observations) {
    std::lock_guard lock(mutex_);
    auto& m = sent_[static_cast<size_t>(topic)];
    auto [it, inserted] = m.try_emplace(point, observations);
    if (inserted) return true;
    // New observers change the representative descriptor and viewing range.
    if (it->second == observations) return false;
    it->second = observations;
    return true;
  }
  bool sent(communication::Topic topic, core::Id point) const {
    std::lock_guard lock(mutex_);
    return sent_[static_cast<size_t>(topic)].count(point) > 0;
  }
  // Whether a position update is worth sending: the point moved by more than `min_move` since
  // the position last sent on `topic` (recorded when it is).
  bool moved(communication::Topic topic, core::Id point, const Eigen::Vector3d& position, double min_move) {
    std::lock_guard lock(mutex_);
    auto [it, inserted] = positions_[static_cast<size_t>(topic)].try_emplace(point, position);
    if (inserted) return true;
    if ((it->second - position).squaredNorm() < min_move * min_move) return false;
    it->second = position;
    return true;
  }
  void mark(communication::Topic topic, core::Id point, int observations) {
    std::lock_guard lock(mutex_);
    sent_[static_cast<size_t>(topic)][point] = observations;
  }

 private:
  mutable std::mutex mutex_;
  std::array<std::unordered_map<core::Id, int>, communication::kTopicCount> sent_;
  std::array<std::unordered_map<core::Id, Eigen::Vector3d>, communication::kTopicCount> positions_;
};

}  // namespace hiveslam::distribution
