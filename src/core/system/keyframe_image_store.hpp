#pragma once
// The grey images of the keyframes this node made, kept for the re-measurement of their
// observations at the end of a run (optim/remeasure_observations.hpp): patch alignment needs the
// very images the corners were found in, and only the node that tracked them has them (a
// keyframe travels as features, never as an image).
//
// Level 0 only (361 KB at 752x480). The pyramids are built for the pass that needs them, the
// latest few dozen kept (levels 1-7 hold 2.1 times level 0: all of sweep's together were 95 MB
// more at the pass), and released after it. Past the byte budget no more images are kept: those
// keyframes' observations stay as detected.
#include <deque>
#include <functional>
#include <list>
#include <memory>
#include <mutex>
#include <unordered_map>

#include "core/features/image_pyramid.hpp"
#include "core/map/ids.hpp"

namespace hiveslam::core {

class KeyframeImageStore {
 public:
  explicit KeyframeImageStore(size_t budget_bytes, size_t cached_pyramids = 48)
      : budget_(budget_bytes), cached_(cached_pyramids) {}
  // Keeps a copy of `gray` (tracking thread, as the keyframe is made).
  void keep(Id keyframe, const cv::Mat& gray);
  bool empty() const;
  size_t bytes() const;
  // The pyramid of a kept image (null when none was kept), built when not in the cache.
  std::shared_ptr<const features::ImagePyramid> pyramid(Id keyframe, int levels, double scale_factor);
  void releasePyramids();
  size_t pyramidsBuilt() const;
  // Drops the images of keyframes `live` says are gone (culled: no pass will measure their
  // observations again), all but the `recent` last kept, whose keyframes may still wait for local
  // mapping to enter their map. Returns how many were dropped.
  size_t retain(const std::function<bool(Id)>& live, size_t recent);

 private:
  mutable std::mutex mutex_;
  size_t budget_, cached_, bytes_ = 0, built_ = 0;
  std::unordered_map<Id, cv::Mat> images_;
  std::deque<Id> order_;  // of keeping
  // Most recently used first.
  std::list<std::pair<Id, std::shared_ptr<const features::ImagePyramid>>> pyramids_;
};

}  // namespace hiveslam::core
