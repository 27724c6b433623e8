#pragma once
// What each topic's receivers hold of every map point: the matching data (descriptor, viewing
// direction, distance range) last sent in full, and the position last sent. Later messages on
// the topic send a point's position only, and its full record again only when the matching
// data changed enough to matter. Thread-safe.
#include <Eigen/Core>
#include <array>
#include <cmath>
#include <mutex>
#include <unordered_map>

#include "communication/message.hpp"
#include "core/features/hamming.hpp"
#include "core/map/ids.hpp"
#include "distribution/wire/records.hpp"

namespace hiveslam::distribution {

// How much a point's matching data may change before its receivers need it again. Tracking
// skips points seen more than 60 degrees off their viewing direction and predicts the pyramid
// level from the distance range in steps of 20%, far coarser than a few degrees or percent. A
// new descriptor, the median of the observations' own, is another view of the same point: on
// bigloop it differed from the last by 14 bits at the median, where matching accepts 50-100.
struct AppearanceTolerance {
  double normal_deg = 0;
  double range_ratio = 0;
  int descriptor_bits = 0;
};

class SentLedger {
 public:
  // True when `p` must go in full on `topic` (and records that it does): never sent there, or
  // its descriptor, direction or range changed past `tolerance`. New observers change these a
  // little each time; the descriptor, a median, often not at all.
  bool needsFull(communication::Topic topic, const PointRecord& p, const AppearanceTolerance& tolerance) {
    std::lock_guard lock(mutex_);
    auto [it, inserted] = sent_[static_cast<size_t>(topic)].try_emplace(p.id, Held(p));
    if (inserted) return true;
    const Held& held = it->second;
    const double cos_turn = held.normal.dot(p.normal);
    const bool same = features::hamming(held.descriptor.data(), p.descriptor.data()) <= tolerance.descriptor_bits &&
                      cos_turn >= std::cos(tolerance.normal_deg * M_PI / 180.0) * held.normal.norm() * p.normal.norm() &&
                      std::abs(p.max_distance - held.max_distance) <= tolerance.range_ratio * held.max_distance &&
                      std::abs(p.min_distance - held.min_distance) <= tolerance.range_ratio * held.min_distance;
    if (same) return false;
    it->second = Held(p);
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
  // `p` went in full on `topic` by another way (a keyframe message).
  void mark(communication::Topic topic, const PointRecord& p) {
    std::lock_guard lock(mutex_);
    sent_[static_cast<size_t>(topic)].insert_or_assign(p.id, Held(p));
  }

 private:
  // A full record's matching data, as its receivers hold it.
  struct Held {
    explicit Held(const PointRecord& p)
        : descriptor(p.descriptor), normal(p.normal), min_distance(p.min_distance), max_distance(p.max_distance) {}
    std::array<uint8_t, 32> descriptor;
    Eigen::Vector3d normal;
    double min_distance, max_distance;
  };

  mutable std::mutex mutex_;
  std::array<std::unordered_map<core::Id, Held>, communication::kTopicCount> sent_;
  std::array<std::unordered_map<core::Id, Eigen::Vector3d>, communication::kTopicCount> positions_;
};

}  // namespace hiveslam::distribution
