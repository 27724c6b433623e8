// DistributedNode: what a node adds to `hiveslam run`'s report.
#include <algorithm>
#include <unordered_set>

#include "distribution/distributed_node.hpp"

namespace hiveslam::distribution {

using communication::Task;
using communication::taskBit;

nlohmann::json DistributedNode::report(double seconds) const {
  nlohmann::json j;
  uint8_t hosted = 0;
  {
    std::lock_guard lock(mutex_);
    hosted = run_hosted_ ? run_hosted_ : plan_.hosted;
  }
  j["task"] = communication::taskName(options_.task);
  j["tasks"] = nlohmann::json::array();
  for (Task t : {Task::Tracking, Task::Mapping, Task::LoopClosing})
    if (hosted & taskBit(t)) j["tasks"].push_back(communication::taskName(t));
  uint64_t bytes_out = 0, bytes_in = 0, msgs_out = 0, msgs_in = 0, kf_msgs = 0, map_msgs = 0;
  nlohmann::json topics = nlohmann::json::object();
  for (const auto& [name, t] : transport_.traffic()) {
    topics[name] = {{"bytes_out", t.bytes_out},       {"bytes_in", t.bytes_in},
                    {"messages_out", t.messages_out}, {"messages_in", t.messages_in},
                    {"writes_failed", t.writes_failed}, {"messages_lost", t.messages_lost},
                    {"messages_refused", t.messages_refused}};
    bytes_out += t.bytes_out;
    bytes_in += t.bytes_in;
    msgs_out += t.messages_out;
    msgs_in += t.messages_in;
    if (name.find("keyframes") != std::string::npos)
      kf_msgs += t.messages_out + t.messages_in;
    else
      map_msgs += t.messages_out + t.messages_in;
  }
  const double s = std::max(seconds, 1e-9);
  j["bytes_out"] = bytes_out;
  j["bytes_in"] = bytes_in;
  j["messages_out"] = msgs_out;
  j["messages_in"] = msgs_in;
  j["topics"] = topics;
  j["bandwidth_mbps"] = (bytes_out + bytes_in) * 8.0 / s / 1e6;
  j["keyframe_msgs_hz"] = kf_msgs / s;
  j["map_msgs_hz"] = map_msgs / s;
  j["local_maps_sent"] = handler_->localMapsSent();
  j["global_maps_sent"] = handler_->globalMapsSent();
  j["maps_received"] = handler_->mapsReceived();
  j["keyframes_published"] = publisher_->published();
  j["keyframes_received"] = subscriber_->received();
  j["messages_dropped"] = subscriber_->dropped() + handler_->dropped();
  {
    std::lock_guard lock(mutex_);
    j["globals_ignored"] = globals_ignored_;
    j["local_maps_held"] = local_maps_held_;
    j["maps_awaited"] = maps_awaited_;
    j["maps_asked_for"] = maps_asked_for_;
    j["keyframes_taken_back"] = keyframes_taken_back_;
    if (!ack_ms_.empty()) j["keyframe_ack_ms"] = ackSummary(ack_ms_);
    if (!released_names_.empty()) j["peers_released"] = released_names_;
    j["stale_points_carried"] = integrator_.stalePointsCarried();
    j["peers"] = peers_at_end_.value_or(peers_.size());
  }
  j["s_full_keyframes"] = observer_.keyframeCount();
  j["s_full_keyframes_not_in_map"] = sFullKeyframesNotInMap();
  return j;
}

nlohmann::json DistributedNode::ackSummary(std::vector<double> ms) {
  std::sort(ms.begin(), ms.end());
  auto at = [&](double q) { return ms[std::min(ms.size() - 1, static_cast<size_t>(q * static_cast<double>(ms.size())))]; };
  return {{"count", ms.size()}, {"median", at(0.5)}, {"p95", at(0.95)}, {"max", ms.back()}};
}

std::vector<core::Id> DistributedNode::sFullKeyframesNotInMap() const {
  std::unordered_set<core::Id> held;
  for (const auto& map : slam_.liveMaps()) {
    std::lock_guard lock(map->mutex);
    for (const auto& [id, kf] : map->keyframes) held.insert(id);
  }
  std::vector<core::Id> missing;
  for (const auto& [id, pose] : observer_.digest().keyframes)
    if (!held.count(id)) missing.push_back(id);
  std::sort(missing.begin(), missing.end());
  return missing;
}

}  // namespace hiveslam::distribution
