#include "viz/live_view.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

namespace hiveslam::viz {

LiveView::LiveView() : start_(std::chrono::steady_clock::now()) {}

double LiveView::seconds() const {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
}

namespace {

void pushEvent(NodeState& n, double seconds, std::string text) {
  n.events.push_back({seconds, std::move(text)});
  ++n.events_total;
  if (n.events.size() > LiveView::kKeptEvents) n.events.pop_front();
}

}  // namespace

void LiveView::changed() {
  ++version_;
  cv_.notify_all();
}

void LiveView::setFrame(const std::string& node, LiveFrame frame, bool extend_path) {
  const double now = seconds();
  std::lock_guard lock(mutex_);
  NodeState& n = nodes_[node];
  const bool was_tracked = n.frame && n.frame->tracked;
  if (frame.tracked && extend_path) {
    n.path.push_back({frame.timestamp, frame.map, frame.T_wc});
    if (n.path.size() > kMaxPathPoses) {
      size_t kept = 0;
      for (size_t i = 0; i < n.path.size(); i += 2) n.path[kept++] = n.path[i];
      if (n.path.size() % 2 == 0) n.path[kept++] = n.path.back();
      n.path.resize(kept);
      ++n.path_epoch;
    }
  }
  if (was_tracked && !frame.tracked) pushEvent(n, now, fmt::format("tracking lost at frame {}", frame.index));
  n.frame = std::move(frame);
  ++n.frame_version;
  changed();
}

void LiveView::setPath(const std::string& node, std::vector<PathPose> path) {
  std::lock_guard lock(mutex_);
  NodeState& n = nodes_[node];
  n.path = std::move(path);
  ++n.path_epoch;
  changed();
}

void LiveView::setScene(const std::string& node, std::shared_ptr<const MapScene> scene) {
  std::lock_guard lock(mutex_);
  NodeState& n = nodes_[node];
  n.scene = std::move(scene);
  ++n.scene_version;
  changed();
}

void LiveView::setPanel(const std::string& node, nlohmann::json panel) {
  const double now = seconds();
  std::lock_guard lock(mutex_);
  NodeState& n = nodes_[node];
  if (n.panel_version > 0)
    for (auto& text : panelEvents(n.panel, panel)) pushEvent(n, now, std::move(text));
  n.panel = std::move(panel);
  ++n.panel_version;
  changed();
}

void LiveView::addEvent(const std::string& node, std::string text) {
  const double now = seconds();
  std::lock_guard lock(mutex_);
  pushEvent(nodes_[node], now, std::move(text));
  changed();
}

void LiveView::removeNode(const std::string& node) {
  std::lock_guard lock(mutex_);
  if (nodes_.erase(node)) changed();
}

uint64_t LiveView::version() const {
  std::lock_guard lock(mutex_);
  return version_;
}

bool LiveView::waitForChange(uint64_t seen, std::chrono::milliseconds timeout) const {
  std::unique_lock lock(mutex_);
  cv_.wait_for(lock, timeout, [&] { return closed_ || version_ != seen; });
  return !closed_;
}

void LiveView::close() {
  std::lock_guard lock(mutex_);
  closed_ = true;
  cv_.notify_all();
}

bool LiveView::closed() const {
  std::lock_guard lock(mutex_);
  return closed_;
}

void LiveView::read(const std::function<void(const std::map<std::string, NodeState>&)>& f) const {
  std::lock_guard lock(mutex_);
  f(nodes_);
}

std::vector<std::string> panelEvents(const nlohmann::json& before, const nlohmann::json& after) {
  std::vector<std::string> events;
  auto count = [](const nlohmann::json& j, const char* key) -> int64_t {
    const auto it = j.find(key);
    return it != j.end() && it->is_number() ? it->get<int64_t>() : 0;
  };
  const int64_t peers_before = count(before, "peers"), peers_after = count(after, "peers");
  if (peers_after > peers_before) events.push_back(fmt::format("peer joined ({} now)", peers_after));
  if (peers_after < peers_before) events.push_back(fmt::format("peer left ({} now)", peers_after));
  const auto tasks_before = before.value("tasks", nlohmann::json::array());
  const auto tasks_after = after.value("tasks", nlohmann::json::array());
  if (tasks_before != tasks_after) {
    std::vector<std::string> names;
    for (const auto& t : tasks_after) names.push_back(t.get<std::string>());
    events.push_back(fmt::format("tasks now {}", names.empty() ? "none" : fmt::format("{}", fmt::join(names, ","))));
  }
  if (count(after, "loops") > count(before, "loops")) events.push_back("loop closed");
  if (count(after, "merges") > count(before, "merges")) events.push_back("maps merged");
  if (count(after, "maps_made") > count(before, "maps_made")) events.push_back("new map");
  return events;
}

}  // namespace hiveslam::viz
