#include "distribution/observer.hpp"

#include <spdlog/spdlog.h>

namespace hiveslam::distribution {

Id Observer::resolve(Id map) const {
  // A chain of merges is short; bounded all the same against a cycle in hostile records.
  for (size_t hops = 0; hops <= merged_into_.size(); ++hops) {
    auto it = merged_into_.find(map);
    if (it == merged_into_.end()) break;
    map = it->second;
  }
  return map;
}

void Observer::record(const KeyFrameRecord& k) {
  std::lock_guard lock(mutex_);
  if (erased_keyframes_.count(k.id)) return;
  auto& stored = keyframes_[k.id];
  const bool keep_links = !k.links && stored.id == k.id;
  KeyFrameRecord light = k;
  // Sent before its sender applied a merge that this node has: S_full files it under the map
  // it lives in now (under the old map, no later snapshot could prune it, and TR's S_full
  // ended a run listing a keyframe its map had culled).
  light.map = resolve(k.map);
  light.full = false;
  light.frame = core::Frame();
  if (keep_links) {
    light.links = true;
    light.parent = stored.parent;
    light.matches = std::move(stored.matches);
    light.loop_edges = std::move(stored.loop_edges);
  }
  stored = std::move(light);
}

void Observer::record(const PointRecord& p, Id map) {
  std::lock_guard lock(mutex_);
  if (erased_points_.count(p.id)) return;
  if (map != kNoId) point_map_[p.id] = resolve(map);
  auto it = points_.find(p.id);
  // A position alone is not a point yet (as in the core map: StateIntegrator::applyPoint).
  if (it == points_.end() && !p.full) return;
  if (it == points_.end() || p.full) {
    points_[p.id] = p;
  } else {
    it->second.position = p.position;
  }
}

void Observer::record(const MapRecord& m) {
  if (!m.merged_maps.empty()) {
    std::lock_guard lock(mutex_);
    const std::unordered_set<Id> merged(m.merged_maps.begin(), m.merged_maps.end());
    for (Id id : merged)
      if (id != m.map) merged_into_[id] = m.map;
    for (auto& [id, k] : keyframes_)
      if (merged.count(k.map)) k.map = m.map;
    for (auto& [id, map] : point_map_)
      if (merged.count(map)) map = m.map;
  }
  for (const auto& k : m.keyframes) record(k);
  for (const auto& p : m.points) record(p, m.map);
  for (Id id : m.erased_keyframes) eraseKeyframe(id);
  for (Id id : m.erased_points) erasePoint(id);
  for (const auto& [old, by] : m.replaced_points) erasePoint(old);
}

void Observer::eraseKeyframe(Id id) {
  std::lock_guard lock(mutex_);
  keyframes_.erase(id);
  erased_keyframes_.insert(id);
}

void Observer::prune(const MapRecord& snapshot, const std::unordered_set<Id>& keyframes,
                     const std::unordered_set<Id>& points, const std::function<bool(Id)>& keyframe_known,
                     const std::function<bool(Id)>& point_known) {
  std::lock_guard lock(mutex_);
  std::unordered_set<Id> maps(snapshot.merged_maps.begin(), snapshot.merged_maps.end());
  maps.insert(snapshot.map);
  // A point with no map on record (none should be) is judged as before: leaving it could leave
  // S_full holding what every other node erased.
  const auto of_snapshot = [&](Id point) {
    auto m = point_map_.find(point);
    return m == point_map_.end() || maps.count(m->second) > 0;
  };
  for (auto it = keyframes_.begin(); it != keyframes_.end();)
    if (maps.count(it->second.map) && !keyframes.count(it->first) && keyframe_known(it->first)) {
      erased_keyframes_.insert(it->first);
      it = keyframes_.erase(it);
    } else {
      ++it;
    }
  for (auto it = points_.begin(); it != points_.end();)
    if (!points.count(it->first) && point_known(it->first) && of_snapshot(it->first)) {
      erased_points_.insert(it->first);
      point_map_.erase(it->first);
      it = points_.erase(it);
    } else {
      ++it;
    }
}

bool Observer::erasedPoint(Id id) const {
  std::lock_guard lock(mutex_);
  return erased_points_.count(id) > 0;
}

bool Observer::erasedKeyframe(Id id) const {
  std::lock_guard lock(mutex_);
  return erased_keyframes_.count(id) > 0;
}

void Observer::revive(const MapRecord& snapshot) {
  std::lock_guard lock(mutex_);
  for (const auto& k : snapshot.keyframes) erased_keyframes_.erase(k.id);
  for (const auto& p : snapshot.points) erased_points_.erase(p.id);
}

void Observer::erasePoint(Id id) {
  std::lock_guard lock(mutex_);
  points_.erase(id);
  point_map_.erase(id);
  erased_points_.insert(id);
}

std::optional<std::vector<MapRecord>> Observer::collectGlobal(MapRecord&& batch, uint16_t sender) {
  std::lock_guard lock(mutex_);
  const std::pair<Id, uint16_t> key{batch.map, sender};
  auto& pending = pending_global_[key];
  // A sender's batches arrive in the order it sent them, one global map after the other: a
  // batch of another update means the one pending was cut short (or began before this node
  // listened).
  if (!pending.empty() && (pending.front().epoch != batch.epoch || pending.front().update != batch.update ||
                           pending.front().batches != batch.batches)) {
    if (pending.front().epoch > batch.epoch) return std::nullopt;  // a late batch of an older update
    spdlog::info("global map {} from node {} cut short: {} of its {} batches came", batch.map, sender, pending.size(),
                 pending.front().batches);
    pending.clear();
  }
  for (const auto& b : pending)
    if (b.batch == batch.batch) return std::nullopt;  // duplicate
  pending.push_back(std::move(batch));
  if (pending.size() < pending.front().batches) return std::nullopt;
  std::vector<MapRecord> all = std::move(pending);
  pending_global_.erase(key);
  return all;
}

size_t Observer::dropPendingGlobals(uint16_t sender) {
  std::lock_guard lock(mutex_);
  size_t dropped = 0;
  std::erase_if(pending_global_, [&](const auto& entry) {
    if (entry.first.second != sender) return false;
    dropped += entry.second.size();
    return true;
  });
  return dropped;
}

bool Observer::hasPoint(Id id) const {
  std::lock_guard lock(mutex_);
  return points_.count(id) > 0;
}

StateDigest Observer::digest() const {
  std::lock_guard lock(mutex_);
  StateDigest d;
  for (const auto& [id, k] : keyframes_) d.keyframes[id] = k.T_cw;
  for (const auto& [id, p] : points_) d.points[id] = p.position;
  return d;
}

size_t Observer::keyframeCount() const {
  std::lock_guard lock(mutex_);
  return keyframes_.size();
}

}  // namespace hiveslam::distribution
