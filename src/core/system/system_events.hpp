#pragma once
// The seam between the SLAM core and the distribution layer (docs/ARCHITECTURE.md): the core
// reports what it made and changed through these calls, and takes keyframes, maps and hosting
// changes in through SlamSystem. Nothing here knows about networks.
#include <memory>

#include "core/loop/loop_closer.hpp"
#include "core/map/map.hpp"

namespace hiveslam::core {

class SystemEvents {
 public:
  virtual ~SystemEvents() = default;
  // Tracking initialized a new map (tracking thread).
  virtual void mapCreated(const std::shared_ptr<Map>&) {}
  // Tracking failed on a frame after tracking the one before (tracking thread).
  virtual void trackingLost() {}
  // Tracking made a keyframe that local mapping will process elsewhere; it is already in the
  // map, linked to the points tracking matched (tracking thread).
  virtual void keyframeCreated(const std::shared_ptr<Map>&, const std::shared_ptr<KeyFrame>&) {}
  // Local mapping made a keyframe's new points and fused duplicates, and is about to run local
  // BA (mapping thread, no lock held).
  virtual void keyframeTriangulated(const std::shared_ptr<Map>&, const std::shared_ptr<KeyFrame>&) {}
  // Local mapping finished a keyframe: points triangulated and fused, local BA applied
  // (mapping thread).
  virtual void keyframeMapped(const std::shared_ptr<Map>&, const std::shared_ptr<KeyFrame>&) {}
  // Loop closing changed a map's coordinate frame (loop closing thread, no lock held).
  virtual void globalUpdate(const GlobalUpdate&) {}
};

// Which of the three modules run in this process. Tracking runs wherever frames come in.
struct Hosting {
  bool mapping = true;
  bool loop_closing = true;
};

}  // namespace hiveslam::core
