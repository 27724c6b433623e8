#pragma once
// The tracking module: for every frame, the camera pose against the current map (constant
// velocity prediction, reference keyframe fallback, local map refinement), the keyframe
// decision, relocalization when lost, and two-view initialization of new maps.
#include <functional>
#include <memory>
#include <optional>

#include "core/map/map.hpp"
#include "core/matching/projection_matcher.hpp"
#include "core/place/keyframe_database.hpp"
#include "core/place/vocabulary.hpp"
#include "core/system/slam_settings.hpp"

namespace hiveslam::core {

enum class TrackingState { NotInitialized, Ok, Lost };

// One inlier match of a tracked frame: the map point and where the frame saw it.
struct FrameObservation {
  Id point;
  Eigen::Vector2f uv;  // undistorted pixel
  uint8_t octave;
};

struct TrackingOutput {
  TrackingState state = TrackingState::NotInitialized;
  bool tracked = false;
  Eigen::Isometry3d T_cw = Eigen::Isometry3d::Identity();
  std::shared_ptr<KeyFrame> reference;      // the pose is kept relative to it
  RelativePose T_c_ref;                     // taken under the map lock
  std::shared_ptr<KeyFrame> new_keyframe;   // for local mapping (also the initial two)
  std::shared_ptr<Map> new_map;             // set when initialization created a map
  bool map_switched = false;                // relocalized in a map other than the last one
  // This frame is the first view of an initialization attempt: if the attempt succeeds, the new
  // map's first keyframe (its origin) is made of it, and only new_map tells of that keyframe.
  bool initialization_reference = false;
  int inliers = 0;
  // The frame's inlier matches: which point each keypoint saw, for SlamSystem::refineFrames.
  std::vector<FrameObservation> observations;
};

class Tracker {
 public:
  Tracker(const SlamSettings& settings, IdGenerator& ids, std::vector<double> scales);

  // mapping_idle: local mapping has no keyframe waiting (keyframe decision input).
  TrackingOutput track(Frame frame, bool mapping_idle);
  // Offline runs (frames as fast as possible) set this: when a keyframe is due but local
  // mapping is busy, tracking waits for it instead of skipping the keyframe, so the map keeps
  // up with a camera that moves faster than real time. It is called without the map lock.
  void setWaitForMapping(std::function<void()> wait) { wait_for_mapping_ = std::move(wait); }
  // Place recognition: keyframes get their bag of words, relocalization asks the database.
  void setPlaceRecognition(const place::Vocabulary* vocabulary, const KeyframeDatabase* database) {
    vocabulary_ = vocabulary;
    database_ = database;
  }
  // The live map a place of the keyframe database belongs to (null if merged away or gone):
  // with it, a lost tracker relocalizes in every map, not only in the one it lost.
  void setMapFinder(std::function<std::shared_ptr<Map>(const Map*)> find) { map_finder_ = std::move(find); }
  // Starts lost in a loaded map: the next frames relocalize in it.
  void startInMap(const std::shared_ptr<Map>& map);
  // Localization only: track against the map, never make keyframes or new maps.
  void setLocalizationOnly(bool on) { localization_only_ = on; }
  TrackingState state() const { return state_; }
  int failures() const { return failures_; }
  // Times tracking went on in a map other than the one it had lost (or was starting).
  int relocalizedInKnownMap() const { return relocalized_in_known_map_; }
  // Frames at which a keyframe was due but mapping was busy (real-time runs): how often the
  // keyframe decision waited on mapping, local or remote.
  int keyframesDeferred() const { return keyframes_deferred_; }
  // Made while mapping was busy: a keyframe overdue by keyframe_max_frames or tracking weak.
  int keyframesMadeBusy() const { return keyframes_made_busy_; }
  const std::shared_ptr<Map>& map() const { return map_; }

 private:
  struct Tracked {
    Frame frame;
    Eigen::Isometry3d T_cw = Eigen::Isometry3d::Identity();
    PointSlots points;
    std::vector<bool> outlier;
  };

  bool initialize(Tracked& current, TrackingOutput& out);
  bool trackWithMotionModel(Tracked& current);
  bool trackReferenceKeyframe(Tracked& current);
  bool trackLocalMap(Tracked& current, int min_inliers);
  // A lost frame's bag of words and the keyframes of every map that look like it, best first.
  struct PlaceQuery {
    place::FeatureVector features;
    std::vector<PlaceCandidate> places;
  };
  PlaceQuery queryPlaces(const Frame& frame) const;
  // At most `max` keyframes of `map` to relocalize against (the caller holds map's mutex).
  std::vector<std::shared_ptr<KeyFrame>> relocalizationCandidates(const PlaceQuery& q, const Map& map, size_t max) const;
  bool relocalize(Tracked& current, const std::vector<std::shared_ptr<KeyFrame>>& candidates,
                  const place::FeatureVector& features);
  // Relocalizes in the maps (other than `skip`) whose keyframes look most like the frame; on
  // success map_ is that map and `lock` holds its mutex.
  bool relocalizeInKnownMap(Tracked& current, const PlaceQuery& q, const Map* skip, std::unique_lock<std::mutex>& lock);
  void describePlace(KeyFrame& kf) const;
  int optimize(Tracked& current);
  // Made, or due but held back because mapping is busy (counted as deferred), or neither.
  enum class KeyframeDecision { None, Make, Deferred };
  // Whether the view has turned more than keyframe_turn_deg from the last keyframe's.
  bool turnedFromKeyframe(const Tracked& current) const;
  KeyframeDecision keyframeDecision(const Tracked& current, bool mapping_idle) const;
  // The point-ratio half of the decision, given trackedShare().
  bool keyframeWanted(const Tracked& current, double share) const;
  // This frame's inliers over the points the reference keyframe tracks (infinite without one).
  double trackedShare() const;
  std::shared_ptr<KeyFrame> makeKeyframe(const Tracked& current);
  // The keyframe a tracked frame's pose is kept relative to (TrackingOutput::reference).
  std::shared_ptr<KeyFrame> nearestKeyframe(const Tracked& current) const;

  SlamSettings settings_;
  IdGenerator& ids_;
  std::vector<double> scales_;
  TrackingState state_ = TrackingState::NotInitialized;
  std::shared_ptr<Map> map_;
  std::shared_ptr<KeyFrame> reference_;
  std::optional<Tracked> last_;
  std::optional<Tracked> init_reference_;          // first frame of an initialization attempt
  std::vector<Eigen::Vector2d> init_prev_matched_;  // where its keypoints were last seen
  Eigen::Isometry3d velocity_ = Eigen::Isometry3d::Identity();
  bool have_velocity_ = false;
  size_t last_keyframe_frame_ = 0;
  Eigen::Matrix3d last_keyframe_R_cw_ = Eigen::Matrix3d::Identity();
  // None until the tracker relocalizes: the stricter checks that follow a relocalization (a
  // pose found by PnP against a place may be wrong) are not for a map just initialized, whose
  // first frames on a forward-moving car hold 40-50 inliers and were dropped as lost.
  std::optional<size_t> last_relocalization_frame_;
  bool relocalizedWithin(const Frame& frame, size_t frames) const {
    return last_relocalization_frame_ && frame.index < *last_relocalization_frame_ + frames;
  }
  int lost_frames_ = 0, failures_ = 0, inliers_ = 0;
  // Keyframes this tracker made for the current map: unlike the map's own count it does not lag
  // behind a busy local mapping thread.
  int keyframes_made_ = 0;
  int keyframes_deferred_ = 0;
  int keyframes_made_busy_ = 0;
  int relocalized_in_known_map_ = 0;
  std::function<std::shared_ptr<Map>(const Map*)> map_finder_;
  // Locks the map tracking is in, after following it into the map it was merged into, if any.
  std::unique_lock<std::mutex> followMerges();
  std::function<void()> wait_for_mapping_;
  const place::Vocabulary* vocabulary_ = nullptr;
  const KeyframeDatabase* database_ = nullptr;
  // The last frame relative to its reference keyframe, and the map epoch it was posed in.
  std::shared_ptr<KeyFrame> last_reference_;
  RelativePose last_T_c_ref_;
  uint64_t epoch_seen_ = 0;
  bool localization_only_ = false;
};

}  // namespace hiveslam::core
