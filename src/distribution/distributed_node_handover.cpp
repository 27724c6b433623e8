// DistributedNode: hand-over (a newcomer gets the maps so far) and lost maps (a node that
// missed a map's first packet asks for it). See "Hand-over" and "Lost map" in the header.
#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>

#include "distribution/distributed_node.hpp"
#include "distribution/packet.hpp"

namespace hiveslam::distribution {

using communication::Message;
using communication::PeerInfo;
using communication::Task;
using communication::Topic;

bool DistributedNode::trackingTookOver(uint16_t asker) const {
  std::lock_guard lock(mutex_);
  auto it = peers_.find(asker);
  return had_mapping_peer_ && it != peers_.end() && it->second.task == Task::Tracking;
}

void DistributedNode::resendGlobalsToTracking() {
  const auto maps = slam_.liveMaps();
  std::lock_guard lock(mutex_);
  if (stopping_) return;
  auto tr = std::find_if(peers_.begin(), peers_.end(), [](const auto& p) { return p.second.task == Task::Tracking; });
  if (tr == peers_.end()) return;
  for (const auto& map : maps) {
    auto it = published_.find(map->id);
    if (it == published_.end()) continue;
    spdlog::info("node {}: map {} of epoch {} sent again, to node {}, the new gateway", options_.id, map->id, it->second,
                 tr->first);
    // A snapshot in full, once TR reads this topic (it began to when LM left).
    handler_->sendGlobal(map, it->second, Topic::LcMap, {}, true, {tr->first, {Topic::LcMap}});
  }
}

void DistributedNode::sendMapsTo(const PeerInfo& peer) {
  // Every task reads the map topic; keyframes go from here to an LM or an LC only.
  Newcomer newcomer{peer.node, {Topic::LmMap}};
  const Plan p = plan();
  if (p.keyframes_to_lm && peer.task == Task::Mapping) newcomer.reads.push_back(Topic::TrKeyframes);
  if (p.keyframes_to_lc && peer.task == Task::LoopClosing) newcomer.reads.push_back(Topic::LmKeyframes);
  for (const auto& map : slam_.liveMaps()) {
    publisher_->push({map, nullptr, Topic::TrKeyframes, 0, true});
    sendSnapshot(map, newcomer);
  }
}

void DistributedNode::sendSnapshot(const std::shared_ptr<core::Map>& map, Newcomer newcomer) {
  std::lock_guard lock(mutex_);
  handler_->sendGlobal(map, synced_[map->id], Topic::LmMap, {}, true, std::move(newcomer));
}

void DistributedNode::awaitMap(core::Id id, uint8_t target) {
  if (slam_.findMap(id)) return;
  const auto start = std::chrono::steady_clock::now();
  const auto wait = std::chrono::milliseconds(options_.settings.handover_wait_ms);
  // A hand-over snapshot comes within a second or so. Later than that, nobody is sending one:
  // the packet that started the map never arrived, and the sender is asked for the map.
  const auto ask_at = start + wait / 5;
  bool asked = false;
  {
    std::lock_guard lock(mutex_);
    ++maps_awaited_;
  }
  spdlog::info("node {}: keyframes of map {} wait for its snapshot", options_.id, id);
  while (!slam_.findMap(id)) {
    const auto now = std::chrono::steady_clock::now();
    const bool ask = !asked && now >= ask_at;
    if (ask) {
      asked = true;
      // Keyframes for loop closing come from the gateway, which reads LC's map topic; those for
      // mapping come from TR, which reads the mapping node's.
      const Topic ask_on = target == kTargetLc ? Topic::LcMap : Topic::LmMap;
      spdlog::info("node {}: asks for map {} (the packet that started it never came)", options_.id, id);
      transport_.publish(ask_on, controlPacket(options_.id, Control::SendMap, id));
    }
    std::unique_lock lock(mutex_);
    maps_asked_for_ += ask;
    if (stopping_ || now >= start + wait) {
      spdlog::warn("node {}: no snapshot of map {} came; its keyframes are mapped without it", options_.id, id);
      return;
    }
    changed_.wait_for(lock, std::chrono::milliseconds(20));
  }
}

void DistributedNode::startHandOverWatch() {
  if (stopping_ || handover_watching_) return;
  handover_watching_ = true;
  // The one before has left its loop (handover_watching_ was false): joined at once.
  if (handover_watch_.joinable()) handover_watch_.join();
  handover_watch_ = std::thread([this] { watchHandOvers(); });
}

void DistributedNode::watchHandOvers() {
  std::unique_lock lock(mutex_);
  while (!stopping_ && !handover_due_.empty()) {
    const auto now = std::chrono::steady_clock::now();
    std::vector<core::Id> missed;
    for (auto it = handover_due_.begin(); it != handover_due_.end();) {
      if (it->second > now) {
        ++it;
        continue;
      }
      // A tracking node back from a partition hands its maps to each returning peer. An LC
      // back after the mapping node finds TR no longer the one to: TR gave mapping and its
      // maps to LM before it heard LC again, and the maps reach LC only as LM's records,
      // without the keyframes' features. LC ended a 30 s cut of TR from both with 14 of the 78
      // keyframes in its map, the others known by their records only.
      const auto adopted = adopt_from_.find(it->first);
      const auto known = known_at_return_.find(it->first);
      if (peers_.count(it->first) && adopted != adopt_from_.end() && known != known_at_return_.end())
        for (core::Id map : known->second)
          if (!adopted->second.count(map)) missed.push_back(map);
      it = handover_due_.erase(it);
    }
    // A snapshot that comes after the end of the sequence lands in the end-of-run exchange,
    // after LC's last corrections: a run that asked then ended with one of LC's points 0.5 m
    // from the other nodes'.
    if (!missed.empty() && !finisher_.joinable()) {
      maps_asked_for_ += static_cast<int>(missed.size());
      lock.unlock();
      for (core::Id map : missed) {
        // The gateway answers with the snapshot a newcomer gets (answerMapRequest).
        spdlog::info("node {}: map {} was not handed over by the tracking node back from a partition; asks the "
                     "gateway for it", options_.id, map);
        transport_.publish(Topic::LcMap, controlPacket(options_.id, Control::SendMap, map));
      }
      lock.lock();
      continue;
    }
    const auto next = std::min_element(handover_due_.begin(), handover_due_.end(),
                                       [](const auto& a, const auto& b) { return a.second < b.second; });
    if (next != handover_due_.end()) changed_.wait_until(lock, next->second);
  }
  handover_watching_ = false;
}

void DistributedNode::answerMapRequest(const Message& m, Topic topic) {
  // Only the node that sends the asker its keyframes answers (LC, say, also reads the mapping
  // node's map topic, where a mapping node asks TR).
  const Plan p = plan();
  if (!(topic == Topic::LcMap ? p.keyframes_to_lc : p.keyframes_to_lm)) return;
  auto map = slam_.findMap(m.map);
  if (!map || map->merged_into.load()) {
    spdlog::info("node {}: node {} asked for map {}, which is not held here", options_.id, m.source, m.map);
    return;
  }
  spdlog::info("node {}: node {} asked for map {}", options_.id, m.source, m.map);
  sendSnapshot(map, {m.source, {Topic::LmMap}});
}

}  // namespace hiveslam::distribution
