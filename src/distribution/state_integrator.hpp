#pragma once
// Records to the core: puts received keyframes, local maps and global maps into this node's
// SLAM maps (S_slam), each under the map's mutex in one step, and records them in the Observer.
//
// Epochs (docs/ARCHITECTURE.md): a global map is applied only when all its batches are in, as
// one correction (core::applyCorrection): keyframes and points it does not cover move with
// their spanning-tree ancestors, so no map ever holds keyframes in two coordinate frames.
#include <memory>

#include "core/system/slam_system.hpp"
#include "distribution/observer.hpp"

namespace hiveslam::distribution {

class StateIntegrator {
 public:
  StateIntegrator(core::SlamSystem& slam, Observer& observer) : slam_(slam), observer_(observer) {}

  // A new keyframe (with its new points and, for a new map, its first keyframe). Returns the
  // core keyframe and its map, not yet given to a module; null when it is already known.
  struct Added {
    std::shared_ptr<core::Map> map;
    std::shared_ptr<core::KeyFrame> keyframe;
  };
  Added addKeyframe(const KeyFrameMessage& m);
  // `stale`: computed before the sender applied this node's latest global map; only what is new
  // here (points, erasures) is taken, the rest is in the old coordinate frame.
  void applyLocal(const MapRecord& m, bool stale = false);
  // All batches of one global map. `authoritative`: the sender's map is the reference (LM's
  // relay): objects missing from it are erased here.
  void applyGlobal(const std::vector<MapRecord>& batches, bool authoritative);

 private:
  std::shared_ptr<core::Map> mapFor(Id id);
  // `authoritative`: the record may bring back a point erased here (see Observer::erasedPoint).
  void applyPoint(core::Map& map, const PointRecord& r, bool authoritative = false);
  // True when the keyframe's point links changed.
  bool relink(core::Map& map, core::KeyFrame& kf, const KeyFrameRecord& r);
  void applyErasures(core::Map& map, const MapRecord& m);
  std::shared_ptr<core::KeyFrame> makeKeyframe(const KeyFrameRecord& r) const;
  core::SlamSystem& slam_;
  Observer& observer_;
};

}  // namespace hiveslam::distribution
