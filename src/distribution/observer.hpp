#pragma once
// The Observer holds S_full: the latest record of every keyframe and map point this node has
// published or received (its own SLAM state S_slam lives in the core maps), with erasures
// applied. It keeps what could not be applied yet (a global map until its last batch) and is
// what nodes compare to check eventual consistency.
//
// Locking: its own mutex, a leaf: taken after a map's mutex or alone, never the other way.
#include <functional>
#include <map>
#include <mutex>
#include <optional>
#include <unordered_map>
#include <unordered_set>

#include "distribution/wire/records.hpp"

namespace hiveslam::distribution {

struct StateDigest {
  std::unordered_map<Id, Eigen::Isometry3d> keyframes;  // T_cw
  std::unordered_map<Id, Eigen::Vector3d> points;
};

class Observer {
 public:
  void record(const KeyFrameRecord& k);  // frame data is not kept (the core keyframe has it)
  void record(const PointRecord& p, Id map);
  // Keyframes, points and erasures of one batch; the records of maps it lists as merged into
  // its map belong to that map from now on, and so do records that come later naming a merged
  // map.
  void record(const MapRecord& m);
  void eraseKeyframe(Id id);
  // After an authoritative snapshot of `snapshot.map`: records of that map (or of the maps it
  // absorbed) that the snapshot lacks and that `keyframe_known` / `point_known` say its sender
  // had go (the sender erased them). Another map's records are not the snapshot's to judge.
  void prune(const MapRecord& snapshot, const std::unordered_set<Id>& keyframes, const std::unordered_set<Id>& points,
             const std::function<bool(Id)>& keyframe_known, const std::function<bool(Id)>& point_known);
  void erasePoint(Id id);
  // Whether the point was erased here (a tombstone: a record from a node that has not heard of
  // the erasure yet must not bring it back).
  bool erasedPoint(Id id) const;
  bool erasedKeyframe(Id id) const;  // likewise
  // An authoritative snapshot lists these as alive: their tombstones go before it is recorded.
  void revive(const MapRecord& snapshot);
  // A global map's batches from `sender` until the last one is in; returns all batches then.
  std::optional<std::vector<MapRecord>> collectGlobal(MapRecord&& batch, uint16_t sender);
  // The sender left or came back as a new incarnation: what it had not finished sending will
  // never be finished (a new incarnation numbers its updates afresh). Returns the batches dropped.
  size_t dropPendingGlobals(uint16_t sender);
  bool hasPoint(Id id) const;
  StateDigest digest() const;
  size_t keyframeCount() const;

 private:
  mutable std::mutex mutex_;
  std::unordered_map<Id, KeyFrameRecord> keyframes_;
  std::unordered_map<Id, PointRecord> points_;
  std::unordered_map<Id, Id> point_map_;  // the map each point record came with
  std::unordered_map<Id, Id> merged_into_;  // a merged map -> the map it went into
  Id resolve(Id map) const;                 // the map a record of `map` belongs to now
  std::unordered_set<Id> erased_keyframes_, erased_points_;
  // Global map batches being collected, by map and sender, for one epoch at a time (a newer
  // epoch drops an unfinished older one). Epochs are counted by each sender: a gateway that
  // joins gets TR's hand-over and LC's next update of the same map at once, and collected by
  // map alone, each dropped the other's batches as those of an older update.
  std::map<std::pair<Id, uint16_t>, std::vector<MapRecord>> pending_global_;
};

}  // namespace hiveslam::distribution
