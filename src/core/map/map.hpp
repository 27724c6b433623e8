#pragma once
// A map: keyframes and map points in one coordinate frame.
//
// Locking rule (the one rule for shared map objects): every read or write of a map's keyframes
// and map points, and of their fields, happens while holding that map's `mutex`. Modules take it
// for one step at a time (a tracking query, a local BA write-back) and never hold two maps'
// mutexes at once.
#include <atomic>
#include <memory>
#include <mutex>
#include <unordered_map>
#include <vector>

#include "core/map/keyframe.hpp"
#include "core/map/map_point.hpp"

namespace hiveslam::core {

class Map {
 public:
  explicit Map(Id id) : id(id) {}
  const Id id;
  mutable std::mutex mutex;
  std::unordered_map<Id, std::shared_ptr<KeyFrame>> keyframes;
  std::unordered_map<Id, std::shared_ptr<MapPoint>> points;
  KeyFrame* origin = nullptr;  // the first keyframe, fixed in optimizations
  // Bumped by every change of the map's coordinate frame (loop correction, merge, global BA):
  // work computed on copies under an older epoch (a local BA) is discarded, and tracking
  // re-poses its last frame through its reference keyframe.
  uint64_t epoch = 0;
  // Set when this map was merged into another; its keyframes and points live on there.
  std::atomic<Map*> merged_into{nullptr};
  // The map that a merged map's contents live in now (itself when not merged).
  Map* resolve() {
    Map* m = this;
    while (Map* next = m->merged_into.load()) m = next;
    return m;
  }
  // Culled keyframes stay alive (frames keep poses relative to them) but leave the map.
  std::vector<std::shared_ptr<KeyFrame>> retired;
  // Erased points stay alive until the next collectGarbage(): a module may still hold a plain
  // pointer or reference to one within the step that erased it.
  std::vector<std::shared_ptr<MapPoint>> erased_points;
  void collectGarbage() { erased_points.clear(); }
  // What left the map, recorded for the distribution layer (which ships it to the other nodes
  // and clears it) when `journal_on`. Standalone runs leave it off.
  struct Journal {
    std::vector<Id> erased_keyframes, erased_points;
    std::vector<std::pair<Id, Id>> replaced_points;  // (old, by) from duplicate fusion
    bool empty() const { return erased_keyframes.empty() && erased_points.empty() && replaced_points.empty(); }
  };
  bool journal_on = false;
  Journal journal;

  void add(const std::shared_ptr<KeyFrame>& kf) { keyframes[kf->id] = kf; }
  void add(const std::shared_ptr<MapPoint>& p) { points[p->id] = p; }
  // Adds the observation both ways.
  static void observe(KeyFrame& kf, int index, const std::shared_ptr<MapPoint>& p);
  // Removes a point from every keyframe that sees it and from the map. These three act only on
  // objects listed in this map (a no-op otherwise: a point of a map merged meanwhile lives on in
  // the other map and must stay whole there).
  void erase(MapPoint& p);
  // Replaces `old` by `by` in every observation (duplicate fusion).
  void replace(MapPoint& old, const std::shared_ptr<MapPoint>& by);
  // Removes a keyframe: its observations go, its children move to its parent.
  void erase(KeyFrame& kf);
  // Moves every keyframe and point of `other` into this map, as they are (a merge; the caller
  // has put them in this map's frame or will), and marks `other` merged into this one. The
  // caller holds both maps' mutexes.
  void absorb(Map& other);
};

}  // namespace hiveslam::core
