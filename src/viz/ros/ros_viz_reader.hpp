#pragma once
// The other end of RosVizPublisher, for `hiveslam view`: finds the nodes publishing under
// /hiveslam/<node>/ on a domain (by discovery, as they come), reads their pose, path, points,
// keyframes and status, and the nodes' announcements, into a LiveView. It only reads: no node
// sees it as a peer (it never announces itself), so it changes no task and no map.
#include <atomic>
#include <map>
#include <memory>
#include <mutex>
#include <set>
#include <string>
#include <thread>

#include "viz/live_view.hpp"

namespace hiveslam::viz::ros {

class RosVizReader {
 public:
  RosVizReader(LiveView& view, int domain);
  ~RosVizReader();
  RosVizReader(const RosVizReader&) = delete;
  RosVizReader& operator=(const RosVizReader&) = delete;
  // Messages read and messages dropped as malformed (a status that is not JSON, a cloud of an
  // unknown layout).
  uint64_t received() const { return received_; }
  uint64_t dropped() const { return dropped_; }

 private:
  void run();
  void follow(const std::string& node);
  struct Impl;
  std::unique_ptr<Impl> impl_;
  LiveView& view_;
  std::atomic<bool> stop_{false};
  std::atomic<uint64_t> received_{0}, dropped_{0};
  std::thread thread_;
};

}  // namespace hiveslam::viz::ros
