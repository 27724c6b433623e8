#pragma once
// The loop closing module (the paper's LC task): for every keyframe local mapping has finished,
// place recognition against the keyframe database; a place of the same map seen by enough
// consecutive keyframes and confirmed geometrically (Sim3 RANSAC on bag-of-words matches, then
// refinement and guided matching) closes a loop: the keyframes around the current one are
// corrected by the Sim3, the two sides fused, the essential graph optimized and a global BA run.
// A place of another map merges that map into this one (Sim3 welding, fusion, global BA).
//
// Threads: process() runs on the loop closing thread. Optimizations run on copies without the
// map mutex and are applied under it, bumping the map's epoch (see map.hpp). The merge is the
// one step that holds two maps' mutexes, taken together by std::scoped_lock.
#include <atomic>
#include <functional>
#include <map>
#include <memory>
#include <set>
#include <unordered_map>
#include <vector>

#include "core/geometry/sim3.hpp"
#include "core/map/map.hpp"
#include "core/optim/remeasurements.hpp"
#include "core/place/keyframe_database.hpp"
#include "core/system/slam_settings.hpp"

namespace hiveslam::core {

struct LoopEvent {
  enum class Kind { Loop, Merge } kind = Kind::Loop;
  double timestamp = 0;  // of the keyframe that recognized the place
  double place_timestamp = 0;  // of the place it recognized
  Id keyframe = kNoId, matched = kNoId;
  Id map = kNoId, merged_map = kNoId;
  int matches = 0;
  double scale = 1.0;   // scale of the correcting Sim3 (drift seen at the loop)
  // Share of the inliers' own depth ratios within 20% of `scale`: near 1 when both sides are
  // one consistent map (figure8's 0.29 loop had 0.98: its map had truly shrunk in a turn).
  double scale_agreement = 0;
  double correct_ms = 0, essential_graph_ms = 0;  // detection to corrected loop; pose graph
};

struct LoopStats {
  int keyframes_checked = 0, loops = 0, merges = 0, global_bas = 0, global_bas_discarded = 0;
  int rejected_geometry = 0;  // consistent places that failed Sim3 verification
  double query_ms_total = 0, global_ba_ms_total = 0;
  double global_ba_sigma = 0;  // the noise the last global BA judged residuals by, in level sigmas
  double global_ba_scale_drift = 1;  // the largest scale change a global BA made and had taken back (>= 1)
  RemeasurementUse remeasured;       // how the last global BA given re-measured observations used them
  std::vector<LoopEvent> events;
  std::vector<std::pair<int, double>> global_ba_ms;  // (keyframes, ms) per global BA
};

// A change of a map's coordinate frame, reported to the distribution layer.
struct GlobalUpdate {
  enum class Kind { Loop, Merge, GlobalBa } kind = Kind::Loop;
  Id map = kNoId;
  Id merged_map = kNoId;  // for a merge: the map that now lives in `map`
};

class LoopCloser {
 public:
  LoopCloser(const SlamSettings& settings, KeyframeDatabase& database, std::vector<double> scales);

  // One keyframe of `map` after local mapping. The caller holds no lock.
  void process(const std::shared_ptr<Map>& map, const std::shared_ptr<KeyFrame>& kf);
  const LoopStats& stats() const { return stats_; }
  // The map tracking works in: another map is merged only into it, so that tracking never finds
  // its own map emptied under it.
  void setActiveMap(const std::atomic<Map*>* active) { active_ = active; }
  // Called on the loop closing thread, without any lock, after each global update is applied.
  void setOnGlobalUpdate(std::function<void(const GlobalUpdate&)> f) { on_update_ = std::move(f); }
  // A global BA of `map` with `iterations` (0: global_ba_iterations), reported as a global
  // update; the end of a run asks for one (SlamSystem::drain). On the loop closing thread, or
  // where no other module runs; the caller holds no lock. `corrected`: a loop or merge has just
  // moved the map, so its starting residuals do not tell outliers from a seam still open.
  // `remeasured`: observations measured again (the end of a run): they replace the detected ones,
  // and a loose solve (a pixel per level, nothing left out) goes first. Judged at once against
  // the map's tight noise, the observations that would pull the map into its new shape look
  // like outliers and sit out: the map stayed at its old scale step.
  // Returns false when the map moved while it ran (a node applied a global map meanwhile):
  // nothing was applied, and the caller may solve again.
  bool globalBundleAdjustment(Map& map, int iterations = 0, bool corrected = false,
                              const Remeasurements* remeasured = nullptr);

 private:
  // A recognized place with its covisibility group (keyframe ids), for the consistency test.
  struct Place {
    KeyFrame* keyframe;
    std::vector<Id> group;
  };
  using Groups = std::vector<std::pair<std::vector<Id>, int>>;
  // Places whose group overlaps a group recognized by the previous keyframes often enough in a
  // row; `groups` becomes this keyframe's groups.
  std::vector<KeyFrame*> consistentPlaces(const std::vector<Place>& places, Groups& groups) const;
  struct Verified;
  bool verify(KeyFrame& kf, KeyFrame& place, Verified& out) const;
  // Points projected into a keyframe with S_cw that find a keypoint with their descriptor;
  // `taken` keypoints are skipped and marked.
  int projectedMatches(const KeyFrame& kf, const Sim3& S_cw, double scale,
                       const std::vector<std::shared_ptr<MapPoint>>& points, std::vector<bool>* taken) const;
  struct LoopCorrection;
  LoopCorrection correctLoop(Map& map, KeyFrame& kf, const Verified& v);
  void mergeMaps(Map& map, KeyFrame& kf, Map& other, const Verified& v);
  void optimizeEssentialGraph(Map& map, const LoopCorrection& c, LoopEvent& event);

  SlamSettings settings_;
  KeyframeDatabase& database_;
  std::vector<double> scales_;
  // Groups (keyframe ids) that recent keyframes recognized, with how many in a row did.
  Groups loop_groups_, merge_groups_;
  int keyframes_since_loop_ = 1000;
  std::unordered_map<Id, size_t> keyframes_at_global_ba_;  // by map: its size at its last global BA
  LoopStats stats_;
  const std::atomic<Map*>* active_ = nullptr;
  std::function<void(const GlobalUpdate&)> on_update_;
  void report(GlobalUpdate::Kind kind, Id map, Id merged = kNoId) const {
    if (on_update_) on_update_({kind, map, merged});
  }
};

}  // namespace hiveslam::core
