#pragma once
// Keyframe and map point identifiers: unique across nodes without coordination, because the
// creating node's id sits in the high 16 bits and a per-node counter in the low 48.
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
    if (node(id) != node_) return;
    const uint64_t next = (id & ((Id{1} << 48) - 1)) + 1;
    uint64_t current = counter_.load();
    while (current < next && !counter_.compare_exchange_weak(current, next)) {
    }
  }

 private:
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
