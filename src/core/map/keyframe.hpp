#pragma once
// A keyframe: a frame kept in the map with its pose, its map point matches (one slot per
// keypoint), covisibility weights (shared map points with other keyframes) and its spanning
// tree parent. Guarded by its map's mutex (see map.hpp).
#include <Eigen/Geometry>
#include <map>
#include <memory>
#include <set>
#include <vector>

#include "core/frame/frame.hpp"
#include "core/map/ids.hpp"
#include "core/place/bow_vector.hpp"

namespace hiveslam::core {

class MapPoint;

class KeyFrame : public std::enable_shared_from_this<KeyFrame> {
 public:
  KeyFrame(Id id, Frame frame, const Eigen::Isometry3d& T_cw)
      : id(id), frame(std::move(frame)), T_cw(T_cw), points(this->frame.size()) {}

  const Id id;
  const Frame frame;
  Eigen::Isometry3d T_cw;
  std::vector<std::shared_ptr<MapPoint>> points;  // per keypoint, null when unmatched
  std::map<KeyFrame*, int, ById> covisibility;          // keyframe -> shared points (>= 15 kept)
  KeyFrame* parent = nullptr;
  std::set<KeyFrame*, ById> children;
  bool bad = false;
  // Bag of words of the image, set before the keyframe is shared and never changed after.
  place::BowVector bow;
  place::FeatureVector bow_features;
  // Loop and merge links: kept by the essential graph, and never culled.
  std::set<KeyFrame*, ById> loop_edges;

  // A culled keyframe keeps its pose relative to its parent (set when it leaves the map): frames
  // tracked against it follow every later correction of the map through pose().
  Eigen::Isometry3d T_c_parent = Eigen::Isometry3d::Identity();
  // Where tracking posed it: the map's epoch then and its pose relative to tracking's reference
  // keyframe. A keyframe that waited in the queue through a correction is re-posed from these.
  uint64_t made_in_epoch = 0;
  KeyFrame* made_from = nullptr;
  Eigen::Isometry3d T_made_from = Eigen::Isometry3d::Identity();
  // The current pose: T_cw, or for a culled keyframe its pose through the spanning tree.
  Eigen::Isometry3d pose() const {
    return bad && parent ? T_c_parent * parent->pose() : T_cw;
  }

  Eigen::Vector3d center() const { return T_cw.inverse().translation(); }
  // Keyframes sharing the most points, best first.
  std::vector<KeyFrame*> bestCovisible(size_t n) const;
  // Rebuilds covisibility from the map points (and links the best neighbour as parent when
  // this keyframe has none).
  void updateConnections();
  int trackedPoints(int min_observations) const;
};

}  // namespace hiveslam::core
