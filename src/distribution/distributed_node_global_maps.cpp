// DistributedNode: global maps (after a loop closure, a merge or a global BA) and the epochs
// that keep a node's keyframes of one map in one coordinate frame.
#include <spdlog/spdlog.h>

#include <algorithm>

#include "core/mapping/keyframe_insertion.hpp"
#include "distribution/distributed_node.hpp"

namespace hiveslam::distribution {

using communication::Task;
using communication::Topic;

void DistributedNode::globalUpdate(const core::GlobalUpdate& u) {
  auto map = slam_.findMap(u.map);
  if (!map) return;
  std::vector<core::Id> merged;
  if (u.merged_map != core::kNoId) merged.push_back(u.merged_map);
  std::lock_guard lock(mutex_);
  // The map is in this epoch's frame from now on, for what this node sends and what it takes.
  const auto note = [&](uint64_t e) {
    std::lock_guard map_lock(map->mutex);
    integrator_.noteEpoch(*map, e);
  };
  if (options_.task == Task::LoopClosing) {
    const uint64_t e = std::max(published_[u.map], synced_[u.map]) + 1;
    published_[u.map] = synced_[u.map] = e;
    note(e);
    handler_->sendGlobal(map, e, Topic::LcMap, merged);
  } else {
    // Labelled even with nobody to send it to: a node that mapped alone (its peers cut off)
    // hands its map over later under this label, which must stand for the frame the map is in
    // now (under the label of before, the returning peers' updates were stale here).
    const uint64_t e = ++synced_[u.map];
    note(e);
    if (plan_.local_maps && !peers_.empty()) handler_->sendGlobal(map, e, Topic::LmMap, merged);
  }
}

void DistributedNode::onGlobal(std::vector<MapRecord>&& batches, Topic topic, uint16_t source) {
  const core::Id map_id = batches.front().map;
  const uint64_t epoch = batches.front().epoch;
  bool adopt = false;
  {
    std::lock_guard lock(mutex_);
    auto it = adopt_from_.find(source);
    adopt = topic == Topic::LmMap && it != adopt_from_.end() && it->second.insert(map_id).second;
  }
  if (adopt) {
    // A tracking node back from a partition mapped on alone: its map holds all it tracked
    // meanwhile, and this node's, older, moved on under labels of its own (LC's global BAs of
    // the map as it was). Judged by labels, TR's map was taken for the older one: a 30 s cut of
    // TR from LM and LC ended at 2.8% of the path against 0.03% uncut.
    adoptWhole(batches, source, "back from a partition");
    return;
  }
  if (topic == Topic::LcMap) {
    releaseHeldUpdates(core::kNoId, nullptr, true);
    if (!holdForAdoption(batches)) applyLoopClosingUpdate(batches);
    return;
  }
  bool ignore = false, newer = false;
  {
    std::lock_guard lock(mutex_);
    auto it = published_.find(map_id);
    // A relay newer than LC's latest update: the gateway's map went on past LC's corrections
    // without it (it took a tracking node's map whole, back from a partition of TR from both;
    // TR's own copy to LC was cut short when TR left). Judged by labels it was ignored, and LC
    // ended with 16 of TR's 85 keyframes.
    newer = it != published_.end() && epoch > it->second;
    // LC takes the relay of its latest update only: an older one would undo a newer correction.
    if (!newer && it != published_.end() && it->second != epoch) {
      ++globals_ignored_;
      ignore = true;
      spdlog::info("node {}: global map {} of epoch {} ignored (this node published epoch {})", options_.id, map_id,
                   epoch, it->second);
    }
  }
  if (newer) {
    adoptWhole(batches, source, "newer than this node's corrections");
    return;
  }
  if (!ignore && integrator_.applyGlobal(batches, true)) {
    {
      std::lock_guard lock(mutex_);
      synced_[map_id] = std::max(synced_[map_id], epoch);
    }
    releaseHeld(map_id);
    return;
  }
  if (!ignore) {
    std::lock_guard lock(mutex_);
    ++globals_ignored_;  // older than the map here (a correction made here, not yet out)
    spdlog::info("node {}: global map {} of epoch {} ignored (the map here has left that frame)", options_.id, map_id,
                 epoch);
  }
  // Still, what is new here (points LM made) and what LM erased is taken, and the keyframes a
  // snapshot brings that this node never got: the one a mapping node mapped as it died, those
  // the node that took mapping back mapped after it gave mapping up again. Without them LC
  // ended such runs two keyframes short of TR and LM.
  for (const auto& b : batches) integrator_.applyLocal(b);  // labelled older: stale here
  for (const auto& a : integrator_.addMissing(batches)) {
    std::lock_guard lock(a.map->mutex);
    core::insertKeyframe(*a.map, *a.keyframe, slam_.scales(), &slam_.database());
  }
}

void DistributedNode::applyLoopClosingUpdate(const std::vector<MapRecord>& batches) {
  // The gateway applies LC's update, then relays its own full state of the map: LC's update
  // plus what LM made meanwhile, in one coordinate frame.
  const core::Id map_id = batches.front().map;
  const uint64_t epoch = batches.front().epoch;
  integrator_.applyGlobal(batches, false);
  std::vector<core::Id> merged;
  for (const auto& b : batches) merged.insert(merged.end(), b.merged_maps.begin(), b.merged_maps.end());
  auto map = slam_.findMap(map_id);
  {
    std::lock_guard lock(mutex_);
    synced_[map_id] = std::max(synced_[map_id], epoch);
    if (map) handler_->sendGlobal(map, epoch, Topic::LmMap, merged);
  }
  releaseHeld(map_id);
}

bool DistributedNode::holdForAdoption(std::vector<MapRecord>& batches) {
  const core::Id map_id = batches.front().map;
  const bool here = slam_.findMap(map_id) != nullptr;  // before mutex_, as in onPeer
  std::lock_guard lock(mutex_);
  // LC may take the returning tracking node's map before this node does (each gets its own
  // copy). Applied to this node's map, which still lacks what TR mapped alone, the relay that
  // follows lists none of those keyframes, and TR erased them as culled here: it ended a 30 s
  // cut from both peers with 19 of the 85 keyframes LM and LC held. Awaited: the maps held here
  // at the return and those not here at all (made during the cut), until taken whole.
  const bool awaited = std::any_of(adopt_from_.begin(), adopt_from_.end(), [&](const auto& a) {
    const auto known = known_at_return_.find(a.first);
    const bool handed_over = !here || (known != known_at_return_.end() && known->second.count(map_id));
    return peers_.count(a.first) && !a.second.count(map_id) && handed_over;
  });
  if (!awaited) return false;
  auto& held = held_updates_[map_id];
  if (!held.batches.empty() && held.batches.front().epoch > batches.front().epoch) return true;  // a newer one waits
  spdlog::info("node {}: LC's update of map {} (epoch {}) waits for the map of a node back from a partition",
               options_.id, map_id, batches.front().epoch);
  if (held.batches.empty()) held.since = std::chrono::steady_clock::now();
  held.batches = std::move(batches);
  return true;
}

void DistributedNode::releaseHeldUpdates(core::Id map, const std::vector<MapRecord>* adopted, bool expired) {
  std::vector<std::vector<MapRecord>> ready;
  {
    std::lock_guard lock(mutex_);
    const auto too_old = std::chrono::steady_clock::now() - std::chrono::milliseconds(options_.settings.handover_wait_ms);
    for (auto it = held_updates_.begin(); it != held_updates_.end();) {
      if ((map != core::kNoId && it->first != map) || (expired && it->second.since > too_old)) {
        ++it;
        continue;
      }
      if (!adopted || StateIntegrator::covers(it->second.batches, *adopted)) {
        ready.push_back(std::move(it->second.batches));
      } else {
        ++globals_ignored_;
        spdlog::info("node {}: LC's update of map {} (epoch {}) dropped: made before LC took the map back from the "
                     "partition", options_.id, it->first, it->second.batches.front().epoch);
      }
      it = held_updates_.erase(it);
    }
  }
  for (const auto& batches : ready) applyLoopClosingUpdate(batches);
}

void DistributedNode::adoptWhole(const std::vector<MapRecord>& batches, uint16_t source, const char* why) {
  const core::Id map_id = batches.front().map;
  const uint64_t epoch = batches.front().epoch;
  integrator_.adoptGlobal(batches);
  {
    std::lock_guard lock(mutex_);
    synced_[map_id] = epoch;
    if (published_.count(map_id)) published_[map_id] = epoch;
    std::erase_if(held_, [&](const MapRecord& m) { return m.map == map_id && m.epoch > epoch; });
  }
  spdlog::info("node {}: map {} taken whole from node {}, {} (epoch {})", options_.id, map_id, source, why, epoch);
  releaseHeld(map_id);
  releaseHeldUpdates(map_id, &batches);
}

uint64_t DistributedNode::knownEpoch(core::Id map) const {
  uint64_t e = 0;
  if (auto it = synced_.find(map); it != synced_.end()) e = it->second;
  if (auto it = published_.find(map); it != published_.end()) e = std::max(e, it->second);
  return e;
}

void DistributedNode::releaseHeld(core::Id map) {
  // Runs on the map handler's thread, like every other apply: arrival order is kept.
  std::vector<MapRecord> ready;
  {
    std::lock_guard lock(mutex_);
    const uint64_t now = knownEpoch(map);
    for (auto it = held_.begin(); it != held_.end();) {
      if (it->map == map && it->epoch <= now) {
        ready.push_back(std::move(*it));
        it = held_.erase(it);
      } else {
        ++it;
      }
    }
  }
  for (const auto& m : ready) integrator_.applyLocal(m);
}

}  // namespace hiveslam::distribution
