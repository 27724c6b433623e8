#pragma once
// Keyframe and map point identifiers: unique across nodes without coordination, because the
// creating node's id sits in the high 16 bits and a per-node counter in the low 48.
// A node that restarts under the same id must not count from 0 again: its peers still hold
// the ids its earlier incarnation made, and a second point with one of them would overwrite
// the first in every map. A distributed node therefore starts its counter at its start time
// in 10 us ticks since 2024 (distribution/distributed_node.cpp): an incarnation would have to
// make more than 100,000 ids a second to reach the next one's range, and 48 bits last 89 years.
#include <atomic>
#include <cstdint>

namespace hiveslam::core {

using Id = uint64_t;
constexpr Id kNoId = ~Id{0};

class IdGenerator {
 public:
  explicit IdGenerator(uint16_t node = 0) : node_(node) {}
  Id next() { return (Id{node_} << 48) | counter_.fetch_add(1, std::memory_order_relaxed); }
  static uint16_t node(Id id) { return static_cast<uint16_t>(id >> 48); }
  // After loading saved maps: this node's next ids come after every id it made before.
  void advancePast(Id id) {
    if (node(id) == node_) advanceTo((id & kCounterMask) + 1);
  }
  // The counter goes on from at least `counter` (never back).
  void advanceTo(uint64_t counter) {
    counter &= kCounterMask;
    uint64_t current = counter_.load();
    while (current < counter && !counter_.compare_exchange_weak(current, counter)) {
    }
  }

 private:
  static constexpr uint64_t kCounterMask = (Id{1} << 48) - 1;
  uint16_t node_;
  std::atomic<uint64_t> counter_{0};
};

// Orders keyframes or map points by id, never by address: containers iterated by the SLAM
// modules must visit elements in the same order on every run (the sequential mode's promise).
struct ById {
  template <typename T>
  bool operator()(const T* a, const T* b) const {
    return a->id < b->id;
  }
};

}  // namespace hiveslam::core
