#pragma once
// A keyframe: a frame kept in the map with its pose, its map point matches (one slot per
// keypoint), covisibility weights (shared map points with other keyframes) and its spanning
// tree parent. Guarded by its map's mutex (see map.hpp).
#include <Eigen/Geometry>
#include <map>
#include <memory>
#include <set>
#include <utility>
#include <vector>

#include "core/frame/frame.hpp"
#include "core/map/flat_map_by_id.hpp"
#include "core/map/ids.hpp"
#include "core/place/bow_vector.hpp"

namespace hiveslam::core {

class MapPoint;

// A camera pose held relative to a keyframe (a tracked frame's, a culled keyframe's): it
// follows the keyframe through every later correction, the map's scale around it included. A
// merge or a loop correction rescales a region by a few percent, and a rigid offset one metre
// long would then be centimetres off.
struct RelativePose {
  Eigen::Isometry3d T_c_k = Eigen::Isometry3d::Identity();
  double scale = 1.0;  // the keyframe's scale() when the pose was taken
};

class KeyFrame : public std::enable_shared_from_this<KeyFrame> {
 public:
  KeyFrame(Id id, Frame frame, const Eigen::Isometry3d& T_cw)
      : id(id), frame(std::move(frame)), T_cw(T_cw), points(this->frame.size()) {}

  const Id id;
  const Frame frame;
  Eigen::Isometry3d T_cw;
  std::vector<std::shared_ptr<MapPoint>> points;  // per keypoint, null when unmatched
  FlatMapById<KeyFrame, int> covisibility;  // keyframe -> shared points (>= 15 kept), by id
  KeyFrame* parent = nullptr;
  std::set<KeyFrame*, ById> children;
  bool bad = false;
  // Bag of words of the image, set before the keyframe is shared and never changed after.
  place::BowVector bow;
  place::FeatureVector bow_features;
  // Per weak corner, the distance to its nearest look-alike in this image (common/look_alikes.hpp;
  // 255 for the others): filled by local mapping, under the map's lock, when it first
  // triangulates with this keyframe.
  std::vector<uint8_t> look_alikes;
  // Loop and merge links: kept by the essential graph, and never culled.
  std::set<KeyFrame*, ById> loop_edges;

  // How much corrections (merges, loop corrections, global BA) have scaled the map around this
  // keyframe since it was made. For a culled keyframe: the value when it was culled.
  double scale_change = 1.0;
  // A culled keyframe follows the live keyframe that shared the most points with it then.
  KeyFrame* anchor = nullptr;
  RelativePose from_anchor;
  // Where tracking posed it: the map's epoch then and its pose relative to tracking's reference
  // keyframe. A keyframe that waited in the queue through a correction is re-posed from these.
  uint64_t made_in_epoch = 0;
  KeyFrame* made_from = nullptr;
  RelativePose made_pose;
  // The current pose and scale change: a live keyframe's own, a culled one's through its anchor.
  Eigen::Isometry3d pose() const { return bad && anchor ? placement().first : T_cw; }
  double scale() const { return bad && anchor ? placement().second : scale_change; }
  // `T_cw` held relative to this keyframe, and back.
  RelativePose relative(const Eigen::Isometry3d& T_cw) const;
  Eigen::Isometry3d poseOf(const RelativePose& r) const;

  Eigen::Vector3d center() const { return T_cw.inverse().translation(); }
  // Keyframes sharing the most points, best first.
  std::vector<KeyFrame*> bestCovisible(size_t n) const;
  // Rebuilds covisibility from the map points (and links the best neighbour as parent when
  // this keyframe has none).
  void updateConnections();
  int trackedPoints(int min_observations) const;

 private:
  std::pair<Eigen::Isometry3d, double> placement() const;
};

}  // namespace hiveslam::core
