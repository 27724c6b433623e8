#pragma once
// The live view's model: per node, the latest frame, the trajectory, a copy of the maps, the
// panel's values and recent events. Sources (a node's own SLAM system, or the ROS topics of a
// running cluster) write it; sinks (the web page, the ROS topics) read it on their own threads
// and wait for changes. Every write is a short copy under one mutex: the tracking thread
// never waits for a sink.
#include <nlohmann/json.hpp>

#include <chrono>
#include <condition_variable>
#include <deque>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "viz/live_frame.hpp"
#include "viz/map_scene.hpp"

namespace hiveslam::viz {

struct NodeEvent {
  double seconds = 0;  // since the view started
  std::string text;
};

struct NodeState {
  std::optional<LiveFrame> frame;
  uint64_t frame_version = 0;
  std::vector<PathPose> path;
  uint64_t path_epoch = 0;  // bumped when the path is replaced, not only extended
  std::shared_ptr<const MapScene> scene;
  uint64_t scene_version = 0;
  nlohmann::json panel = nlohmann::json::object();
  uint64_t panel_version = 0;
  std::deque<NodeEvent> events;  // the newest kKeptEvents
  uint64_t events_total = 0;
};

class LiveView {
 public:
  static constexpr size_t kKeptEvents = 50;
  // A path longer than this is thinned to every second pose (the first and the newest kept) and
  // sent again (path_epoch): a node that runs for hours holds and draws a bounded path, under
  // 2.5 MB with the vector's spare room, where every frame's pose would add 144 bytes (0.17 MB a
  // minute at 20 Hz; a 30-minute soak's TR grew by 0.8 MB a minute in all).
  static constexpr size_t kMaxPathPoses = 10000;
  LiveView();
  // A tracked frame extends the node's path (unless the path comes from elsewhere:
  // extend_path false); a frame lost after a tracked one is an event.
  void setFrame(const std::string& node, LiveFrame frame, bool extend_path = true);
  void setPath(const std::string& node, std::vector<PathPose> path);
  void setScene(const std::string& node, std::shared_ptr<const MapScene> scene);
  // Changes of peers, tasks, maps, loops and merges between two panels become events.
  void setPanel(const std::string& node, nlohmann::json panel);
  void addEvent(const std::string& node, std::string text);
  void removeNode(const std::string& node);

  // Bumped by every write.
  uint64_t version() const;
  // Waits until version() != seen, at most `timeout`; false when closed.
  bool waitForChange(uint64_t seen, std::chrono::milliseconds timeout) const;
  // Wakes every waiter for good (the run ends).
  void close();
  bool closed() const;
  // Runs `f` on the nodes under the lock: copy what is needed and return.
  void read(const std::function<void(const std::map<std::string, NodeState>&)>& f) const;
  double seconds() const;

 private:
  void changed();  // with mutex_ held
  const std::chrono::steady_clock::time_point start_;
  mutable std::mutex mutex_;
  mutable std::condition_variable cv_;
  std::map<std::string, NodeState> nodes_;
  uint64_t version_ = 0;
  bool closed_ = false;
};

// The events between two panels of one node: "peer joined" when `peers` rises, "tasks now tr,lm"
// when `tasks` changes, "loop closed", "maps merged", "new map" when their counts rise.
std::vector<std::string> panelEvents(const nlohmann::json& before, const nlohmann::json& after);

}  // namespace hiveslam::viz
