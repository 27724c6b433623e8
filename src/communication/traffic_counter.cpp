#include "communication/traffic_counter.hpp"

namespace hiveslam::communication {

void TrafficCounter::add(Topic t, size_t bytes, int dir) {
  auto& c = counts_[static_cast<size_t>(t)];
  c.bytes[dir] += bytes;
  ++c.messages[dir];
}

TrafficReport TrafficCounter::report() const {
  TrafficReport r;
  for (int i = 0; i < kTopicCount; ++i) {
    const auto& c = counts_[static_cast<size_t>(i)];
    if (c.messages[0] == 0 && c.messages[1] == 0 && c.writes_failed == 0 && c.lost == 0 && c.refused == 0)
      continue;
    r[topicName(static_cast<Topic>(i))] = {c.bytes[0], c.bytes[1], c.messages[0], c.messages[1], c.writes_failed, c.lost, c.refused};
  }
  return r;
}

}  // namespace hiveslam::communication
