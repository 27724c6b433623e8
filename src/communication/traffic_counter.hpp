#pragma once
// Bytes and messages per topic, both ways: every node measures its own traffic.
#include <array>
#include <atomic>
#include <cstdint>
#include <map>
#include <string>

#include "communication/message.hpp"

namespace hiveslam::communication {

struct TopicTraffic {
  uint64_t bytes_out = 0, bytes_in = 0, messages_out = 0, messages_in = 0;
  // Packets that never went out (a write the middleware refused) or never came (a reliable
  // reader told its writer no longer held them: a reader that fell behind a keep-last history).
  uint64_t writes_failed = 0, messages_lost = 0;
  // Packets refused on arrival: from a participant that is not the node it names, or going
  // back in its writer's sequence (DdsTransport).
  uint64_t messages_refused = 0;
};
using TrafficReport = std::map<std::string, TopicTraffic>;  // by topic name, only topics used

class TrafficCounter {
 public:
  void sent(Topic t, size_t bytes) { add(t, bytes, 0); }
  void received(Topic t, size_t bytes) { add(t, bytes, 1); }
  void writeFailed(Topic t) { ++counts_[static_cast<size_t>(t)].writes_failed; }
  void lost(Topic t, uint64_t messages) { counts_[static_cast<size_t>(t)].lost += messages; }
  uint64_t refused(Topic t) { return ++counts_[static_cast<size_t>(t)].refused; }  // the count so far
  TrafficReport report() const;

 private:
  void add(Topic t, size_t bytes, int dir);
  struct Counts {
    std::atomic<uint64_t> bytes[2]{0, 0}, messages[2]{0, 0};
    std::atomic<uint64_t> writes_failed{0}, lost{0}, refused{0};
  };
  std::array<Counts, kTopicCount> counts_;
};

}  // namespace hiveslam::communication
