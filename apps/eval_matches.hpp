#pragma once
// hiveslam eval matches DATASET: the core's data association judged against the scene a rendered
// sequence was made of.
#include <string>

#include "core/system/slam_settings.hpp"

namespace hiveslam::apps {

struct MatchesOptions {
  int frames = 0;      // 0: all
  bool sharp = false;  // render without motion blur, rolling shutter, tremor and lens error
  bool true_lens = false;  // give the SLAM the lens the images were rendered with, not the nominal one
  // Erase each new point that joins two scene points as local mapping makes it, before its
  // local BA: what the run would be with triangulation's pairs all right.
  bool oracle = false;
};

// Runs the sequential SLAM on a sequence written by `hiveslam synth` (rebuilt from its
// sequence.json, rendered again) and prints, per keyframe, how many of the points local mapping
// made join two different scene points, and per second how many of tracking's inliers are
// matched to another scene point than their map point's, the rotation error since the map's
// first keyframe, the share of each keyframe's points at the wrong distance and the map's scale
// (true metres per map unit) at each keyframe, and at the end the largest map's wrong points and
// the ATE of its frames (as `hiveslam run` reports it).
void evalMatches(const std::string& dataset, const core::SlamSettings& settings, const MatchesOptions& options);

}  // namespace hiveslam::apps
