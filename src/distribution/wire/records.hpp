#pragma once
// The state that crosses the network, as plain records with ids instead of pointers: what a
// node publishes about a keyframe or map point, what the Observer stores as S_full, and what
// the receiving node applies to its SLAM maps. See docs/ARCHITECTURE.md for why each field is
// sent.
#include <Eigen/Geometry>
#include <array>
#include <vector>

#include "core/frame/frame.hpp"
#include "core/map/ids.hpp"

namespace hiveslam::distribution {

using core::Id;
using core::kNoId;

struct PointRecord {
  Id id = kNoId;
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  // Full records (the first time a point is sent, and when these changed: SentLedger) also carry
  // what matching needs: descriptor, viewing direction and distance range.
  bool full = false;
  Id first_keyframe = kNoId;
  std::array<uint8_t, 32> descriptor{};
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();
  double min_distance = 0, max_distance = 0;
};

struct KeyFrameRecord {
  Id id = kNoId;
  Id map = kNoId;
  Eigen::Isometry3d T_cw = Eigen::Isometry3d::Identity();
  // Links (parent, point matches, loop edges) are left out of an update when unchanged since
  // the last one on the same topic: they are most of a keyframe update's bytes.
  bool links = true;
  Id parent = kNoId;
  std::vector<std::pair<uint32_t, Id>> matches;  // keypoint index -> map point
  std::vector<Id> loop_edges;
  // A new keyframe (full) carries its image features and where tracking posed it.
  bool full = false;
  core::Frame frame;
  uint64_t made_in_epoch = 0;
  Id made_from = kNoId;
  Eigen::Isometry3d T_made_from = Eigen::Isometry3d::Identity();
};

// A batch of a local map (after local BA) or of a global map (after loop closure, merge or
// global BA). A global map is complete only with all its batches: it is applied at once.
struct MapRecord {
  enum class Kind : uint8_t { Local = 0, Global = 1 } kind = Kind::Local;
  Id map = kNoId;
  uint64_t epoch = 0;
  uint32_t batch = 0, batches = 1;
  // Which of its sender's global maps this batch belongs to, numbered as the sender captures
  // them. Two global maps can carry one epoch label (a newcomer's snapshot right after the
  // periodic global map it joined during), and their batches must not be collected as one.
  uint32_t update = 0;
  Id origin = kNoId;
  std::vector<KeyFrameRecord> keyframes;
  std::vector<PointRecord> points;
  std::vector<Id> erased_keyframes, erased_points;
  std::vector<std::pair<Id, Id>> replaced_points;  // (old, by)
  std::vector<Id> merged_maps;                     // maps now living in `map`
  // Keyframes whose local mapping got as far as their new points (which this record carries):
  // the gateway's acknowledgement to the tracking node that made them. A keyframe merely
  // listed above is no acknowledgement: it can ride along as a neighbour before it is mapped.
  std::vector<Id> mapped;
};

// A new keyframe with the points it sees that the receiver may not know yet.
struct PointStats {
  Id id = kNoId;
  uint32_t visible = 0, found = 0;  // times tracking predicted it in view / matched it
};

struct KeyFrameMessage {
  KeyFrameRecord keyframe;
  std::vector<PointRecord> points;
  std::vector<KeyFrameRecord> companions;  // a new map's first keyframe travels with its second
  // Tracking's counts for the points local mapping made recently: its culling of weak new
  // points (found / visible below a quarter) needs them, and only tracking sees them.
  std::vector<PointStats> stats;
};

}  // namespace hiveslam::distribution
