#pragma once
// Records to the core: puts received keyframes, local maps and global maps into this node's
// SLAM maps (S_slam), each under the map's mutex in one step, and records them in the Observer.
//
// Epochs (docs/ARCHITECTURE.md): a global map is applied only when all its batches are in, as
// one correction (core::applyCorrection): keyframes and points it does not cover move with
// their spanning-tree ancestors, so no map ever holds keyframes in two coordinate frames.
//
// Every keyframe and local map travels labelled with its sender's global epoch of the map: the
// coordinate frame its poses and points are in. Each node notes, under the map's mutex, which
// of its own core epochs (core::Map::epoch, a count that differs from node to node) each label
// stands for. Content whose label no longer stands for the map's current frame is stale: it
// is carried into the current frame. Deciding that under the same lock as the correction
// leaves no window in which a correction is applied but not yet known.
#include <atomic>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <unordered_map>

#include "core/system/slam_system.hpp"
#include "distribution/observer.hpp"

namespace hiveslam::distribution {

class StateIntegrator {
 public:
  // Content from a node up to this many global updates behind is carried with the map's scale
  // change since; older content is carried without it (the scale taken as unchanged).
  static constexpr size_t kLabelsKept = 16;

  StateIntegrator(core::SlamSystem& slam, Observer& observer) : slam_(slam), observer_(observer) {}

  // A new keyframe (with its new points and, for a new map, its first keyframe). Returns the
  // core keyframe and its map, not yet given to a module. One labelled with an older frame, or
  // posed in a map merged into another since, is re-posed from where tracking posed it
  // (relative to a keyframe both nodes hold) and the points it brings move with it; null when
  // no such keyframe is held. One held already
  // (`held`) came first in a hand-over snapshot taken after it was sent: it is returned as it
  // is (the snapshot's pose is the newer), still to be given to the module it was sent to.
  struct Added {
    std::shared_ptr<core::Map> map;
    std::shared_ptr<core::KeyFrame> keyframe;
    bool held = false;
  };
  Added addKeyframe(const KeyFrameMessage& m, uint64_t label);
  // The keyframes a global map brings with their features (a newcomer's snapshot) that this
  // node does not hold, from a global map it does not apply as a whole (LC takes only the
  // relay of its own latest update). Each is added as a late keyframe is, re-posed from the
  // keyframe tracking posed it from, in id order (one may be posed from another). Not yet
  // given to a module. Call after the batches' new points are in: the keyframes link to them.
  std::vector<Added> addMissing(const std::vector<MapRecord>& batches);
  // A local map labelled with an older frame than the map's (the sender computed it before it
  // applied this node's latest global map): only what is new here (points, erasures) is taken,
  // the points carried into the current frame; the poses are left to a fresh record.
  void applyLocal(const MapRecord& m);
  // A local map labelled with a newer frame than the map's: the sender applied a global map
  // that is still on its way here, and the caller holds the record until it is in. Meanwhile
  // its new points are lent, carried into the map's frame as a stale record's are, and linked
  // to the keyframes that see them: tracking would otherwise see no new point for as long as a
  // global map takes to send. Poses, known points' positions and erasures wait for the record
  // (erasures taken early cost figure8 about 1 mm in 4 of 4 real-time runs).
  void applyAhead(const MapRecord& m);
  // All batches of one global map. `authoritative`: the sender's map is the reference (LM's
  // relay): objects missing from it are erased here. Returns false, having applied nothing
  // or only what a stale local map gives, when it is authoritative but its label stands for
  // a frame the map has left (a correction made here since, its update not yet out): the
  // caller treats it as an ignored update.
  bool applyGlobal(const std::vector<MapRecord>& batches, bool authoritative) { return applyGlobal(batches, authoritative, false); }
  // All batches of one global map, taken whole whatever its label, and the map's earlier labels
  // forgotten: the map of a tracking node back from a partition. It mapped on alone while this
  // node's labels went on without it, so one label can stand for two frames on the two sides.
  void adoptGlobal(const std::vector<MapRecord>& batches);
  // Whether a global update holds every keyframe of `snapshot` that its sender knew of (those
  // older than its own newest keyframe of the same node): an update made from that snapshot or
  // later, not from a map that had not yet taken it.
  static bool covers(const std::vector<MapRecord>& update, const std::vector<MapRecord>& snapshot);
  uint64_t stalePointsCarried() const { return stale_points_carried_; }
  // Whether a node has left the network (and not come back). An authoritative map spares the
  // points its sender may not have heard of yet; a node that left sends none any more, so its
  // points the sender lacks are erased like the rest. Set before the first map comes in; called
  // with a map's mutex held, so it must take no lock of the caller's.
  void setDeparted(std::function<bool(uint16_t node)> departed) { departed_ = std::move(departed); }

  // With the map's mutex held: the map is now in the frame of global epoch `label` (a global
  // map applied here, or made here and published as that epoch).
  void noteEpoch(const core::Map& map, uint64_t label);
  // With the map's mutex held: the label of the map's current frame, for outgoing content.
  uint64_t label(const core::Map& map) const;

 private:
  bool applyGlobal(const std::vector<MapRecord>& batches, bool authoritative, bool whole);
  std::shared_ptr<core::Map> mapFor(Id id);
  // `authoritative`: the record may bring back a point erased here (see Observer::erasedPoint).
  // Returns whether the map holds the point now: only then does S_full record it.
  bool applyPoint(core::Map& map, const PointRecord& r, bool authoritative = false);
  // True when the keyframe's point links changed.
  bool relink(core::Map& map, core::KeyFrame& kf, const KeyFrameRecord& r);
  void applyErasures(core::Map& map, const MapRecord& m);
  // What a stale record (made in a frame this map has left) can still bring: its new points and
  // its erasures, in the map and in S_full alike.
  void takeStale(core::Map& map, const MapRecord& m);
  // A record's new points, from another frame, carried into the map's. With its mutex held.
  void takeNewPoints(core::Map& map, const MapRecord& m);
  // The new points of a local map in another frame (stale or ahead), moved into the map's
  // current frame; those no keyframe of the record held here can carry are left out.
  std::vector<PointRecord> carryNewPoints(const core::Map& map, const MapRecord& m);
  std::shared_ptr<core::KeyFrame> makeKeyframe(const KeyFrameRecord& r) const;
  // With the map's mutex held: content labelled `label` is in an older frame than the map's.
  bool stale(const core::Map& map, uint64_t label) const;
  // With the map's mutex held: content labelled `label` is in the map's current frame.
  bool current(const core::Map& map, uint64_t label) const;
  core::SlamSystem& slam_;
  Observer& observer_;
  std::function<bool(uint16_t)> departed_ = [](uint16_t) { return false; };
  std::atomic<uint64_t> stale_points_carried_{0};
  // What a label stood for here: the core epoch, and each keyframe's scale() then (content of
  // that frame is rescaled by how much the map's scale changed around it since).
  struct Frame {
    uint64_t core_epoch = 0;
    std::unordered_map<Id, double> scales;
  };
  // With the map's mutex held: the frame `label` stood for here; null when unknown.
  const Frame* frameOf(const core::Map& map, uint64_t label) const;  // epochs_mutex_ held
  // Per map, the last kLabelsKept labels. Taken after a map's mutex.
  mutable std::mutex epochs_mutex_;
  std::unordered_map<Id, std::map<uint64_t, Frame>> epochs_;
};

}  // namespace hiveslam::distribution
