// DistributedNode: a tracking node that offloads mapping waits for its gateway's
// acknowledgements, and releases its peers when the link is too slow (see "Slow link" in the
// header).
#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>

#include "distribution/distributed_node.hpp"
#include "distribution/packet.hpp"

namespace hiveslam::distribution {

using communication::PeerInfo;
using communication::Topic;

void DistributedNode::watchGateway(std::chrono::steady_clock::time_point now) {
  // Only in real time does tracking starve: offline, it waits for the gateway instead.
  if (slam_.mode() != core::SlamSystem::Mode::Realtime) return;
  if (stopping_ || releaser_.joinable() || !plan_.keyframes_to_lm || handover_pending_) return;
  const int slow_ms = options_.settings.release_slow_gateway_ms, slow_acks = options_.settings.release_slow_acks;
  const auto starved = [&](const auto& waiting) {
    return std::any_of(waiting.begin(), waiting.end(), [&](const auto& k) { return watch_.starved(now, k.second); });
  };
  std::string why;
  if (lost_waiting_ && (starved(outstanding_) || starved(unanswered_)))
    why = fmt::format("tracking lost with a keyframe unacknowledged for over {} ms",
                      std::max(slow_ms, options_.settings.dead_peer_ms));
  else if (!watch_.tooSlow(now))
    return;
  else if (watch_.slowInARow() >= slow_acks)
    why = fmt::format("{} keyframe acknowledgements in a row took over {} ms", watch_.slowInARow(), slow_ms);
  else
    why = fmt::format("no keyframe acknowledged for {} ms", std::max(slow_ms * slow_acks, options_.settings.dead_peer_ms));
  releaser_ = std::thread([this, why] { releasePeers(why); });
}

void DistributedNode::releasePeers(const std::string& why) {
  std::vector<PeerInfo> gone;
  {
    std::lock_guard lock(mutex_);
    if (stopping_ || peers_.empty()) return;
    for (const auto& [id, p] : peers_) {
      gone.push_back(p);
      released_.insert({id, p.incarnation});
      released_names_.push_back(p.name);
    }
    peers_.clear();
  }
  {
    std::lock_guard lock(departed_mutex_);
    for (const auto& p : gone) departed_.insert(p.node);
  }
  std::string names;
  for (const auto& p : gone) {
    gate_.left(p.node);
    names += (names.empty() ? "" : ", ") + p.name;
  }
  spdlog::warn("node {}: {}: the link is too slow to offload; releasing {} and running alone", options_.id, why, names);
  // LM reads TR's keyframe topic, LC the gateway's map topic (so does LM).
  transport_.publish(Topic::TrKeyframes, controlPacket(options_.id, Control::Release));
  transport_.publish(Topic::LmMap, controlPacket(options_.id, Control::Release));
  applyPlan();  // alone: mapping and loop closing here, the unacknowledged keyframes mapped here
}

bool DistributedNode::remoteIdle() {
  std::lock_guard lock(mutex_);
  // An acknowledgement that never came (the keyframe was dropped at the gateway: its map was
  // merged meanwhile, or the gateway changed) must not hold keyframes back for good.
  const auto now = std::chrono::steady_clock::now();
  const auto lost = now - std::chrono::milliseconds(options_.settings.remote_mapping_wait_ms);
  for (auto it = outstanding_.begin(); it != outstanding_.end();)
    if (it->second < lost) {
      unanswered_.insert(*it);
      it = outstanding_.erase(it);
    } else {
      ++it;
    }
  constexpr size_t kUnansweredKept = 64;  // bounded: an LM that lives on never answers them
  while (unanswered_.size() > kUnansweredKept) unanswered_.erase(unanswered_.begin());
  watchGateway(now);
  return outstanding_.empty();
}

void DistributedNode::remoteWait() const {
  std::unique_lock lock(mutex_);
  changed_.wait_for(lock, std::chrono::milliseconds(options_.settings.remote_mapping_wait_ms),
                    [&] { return outstanding_.empty() || !plan_.keyframes_to_lm; });
}

}  // namespace hiveslam::distribution
