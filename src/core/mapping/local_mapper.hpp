#pragma once
// The local mapping module: inserts keyframes from tracking into the map, culls weak recent
// points, triangulates new points with covisible keyframes, fuses duplicates, runs local BA
// and culls redundant keyframes.
#include <functional>
#include <atomic>
#include <list>
#include <memory>

#include "core/map/map.hpp"
#include "core/place/keyframe_database.hpp"
#include "core/system/slam_settings.hpp"

namespace hiveslam::core {

// Milliseconds local mapping spent per stage, summed over the keyframes it processed. The
// local BA's solve runs without the map lock; the other stages hold it.
struct MappingStageMs {
  double insert = 0;          // the keyframe into the map, its links, garbage collection
  double cull_points = 0;     // recent points that did not hold up
  double triangulate = 0;     // new points with covisible keyframes
  double fuse = 0;            // duplicates merged with the neighbours' points
  double local_ba_setup = 0;  // the problem copied out and the result applied
  double local_ba = 0;        // the solve
  double cull_keyframes = 0;  // redundant keyframes
  double total = 0;
  double max_total = 0;       // the slowest keyframe
};

struct MappingStats {
  int keyframes_processed = 0, points_created = 0, points_culled = 0, keyframes_culled = 0, local_bas = 0,
      local_bas_discarded = 0;
  int local_bas_cut_short = 0;  // stopped early because a newer keyframe was waiting
  MappingStageMs ms;
};

class LocalMapper {
 public:
  LocalMapper(const SlamSettings& settings, IdGenerator& ids, std::vector<double> scales);

  // Runs every step for one keyframe of `map` (the caller holds no lock; each step takes the
  // map's mutex). `abort_ba` lets a newer keyframe cut the local BA short; `before_ba` runs
  // with no lock held once the keyframe's new points are in the map, before local BA. A
  // keyframe culled before its turn (core/mapping/keyframe_insertion.hpp) is not mapped, but
  // `before_ba` still runs: a distributed node acknowledges the keyframe there, and its maker
  // waits for that word.
  void process(const std::shared_ptr<Map>& map, const std::shared_ptr<KeyFrame>& kf,
               const std::atomic<bool>* abort_ba = nullptr, const std::function<void()>& before_ba = {});
  const MappingStats& stats() const { return stats_; }
  // Inserted keyframes enter the place recognition database, culled ones leave it.
  void setDatabase(KeyframeDatabase* database) { database_ = database; }

 private:
  void insert(Map& map, KeyFrame& kf);
  void cullRecentPoints(Map& map, const KeyFrame& kf);
  void triangulateNewPoints(Map& map, KeyFrame& kf);
  // Candidate pairs (kf keypoint, nb keypoint), both free, for new points: on the epipolar band
  // of the relative pose T21 (kf frame -> nb frame), by descriptor.
  std::vector<std::pair<int, int>> epipolarPairs(const KeyFrame& kf, const KeyFrame& nb,
                                                 const Eigen::Isometry3d& T21) const;
  void fuse(Map& map, KeyFrame& kf);
  // Local BA in three steps so that the solve runs without the map lock: tracking keeps going
  // while it optimizes copies of the poses and points.
  struct LocalBa;
  LocalBa prepareLocalBa(Map& map, KeyFrame& kf);
  void applyLocalBa(Map& map, LocalBa& ba);
  void cullKeyframes(Map& map, KeyFrame& kf);

  SlamSettings settings_;
  IdGenerator& ids_;
  std::vector<double> scales_;
  struct Recent {
    std::shared_ptr<MapPoint> point;
    int keyframes_since = 0;
  };
  std::list<Recent> recent_;
  MappingStats stats_;
  KeyframeDatabase* database_ = nullptr;
};

}  // namespace hiveslam::core
