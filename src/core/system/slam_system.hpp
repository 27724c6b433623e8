#pragma once
// The SLAM system of one node: tracking, local mapping and loop closing behind one call per
// frame. Threaded (default): tracking runs on the caller's thread and hands keyframes to the
// local mapping thread through a queue, which hands them on to the loop closing thread.
// Sequential: each frame is tracked, then its keyframe, if any, is mapped and checked for loops
// before the next frame, so the same input always gives the same trajectory.
#include <atomic>
#include <condition_variable>
#include <functional>
#include <mutex>
#include <memory>
#include <thread>
#include <vector>

#include "common/blocking_queue.hpp"

#include "core/camera/camera_model.hpp"
#include "core/loop/loop_closer.hpp"
#include "core/mapping/local_mapper.hpp"
#include "core/optim/remeasure_observations.hpp"
#include "core/system/keyframe_image_store.hpp"
#include "core/system/system_events.hpp"
#include "core/tracking/tracker.hpp"

namespace hiveslam::core {

struct FrameRecord {
  size_t index = 0;
  double timestamp = 0;
  bool tracked = false;
  std::shared_ptr<KeyFrame> reference;
  RelativePose T_c_ref;  // pose relative to the reference
  Id map = kNoId;
  double tracking_ms = 0;
  int inliers = 0;       // map points tracked
  bool keyframe = false;  // the frame became a keyframe
  std::vector<FrameObservation> observations;  // its inlier matches (SlamSettings::refine_frames)
};

class SlamSystem {
 public:
  enum class Mode {
    Sequential,  // lockstep on the caller's thread: deterministic
    Offline,     // threaded; tracking waits for mapping when a keyframe is due (full accuracy)
    Realtime,    // threaded; tracking never waits (keyframes are skipped while mapping is busy)
  };
  // Without a vocabulary there is no loop closing, and relocalization searches recent keyframes.
  SlamSystem(const SlamSettings& settings, std::shared_ptr<const camera::CameraModel> camera, Mode mode,
             std::shared_ptr<const place::Vocabulary> vocabulary = nullptr, uint16_t node = 0);
  ~SlamSystem();
  SlamSystem(const SlamSystem&) = delete;
  SlamSystem& operator=(const SlamSystem&) = delete;
  Mode mode() const { return mode_; }

  // Adds saved maps (io/atlas_file) before the first frame: tracking starts by relocalizing in
  // the largest. With localization_only, no keyframe or map is made: the maps stay as loaded.
  void loadAtlas(const std::vector<std::shared_ptr<Map>>& maps, bool localization_only);

  // Tracks one grey image (and maps its keyframe); returns the frame's record.
  const FrameRecord& process(const cv::Mat& gray, double timestamp);

  // Lets local mapping finish every queued keyframe and stops its thread (idempotent). Results
  // are read after it.
  void finish();

  // The distribution layer's half of the seam (system_events.hpp). Set before the first frame.
  void setEvents(SystemEvents* events) { events_ = events; }
  // Which modules run here; the distribution policy changes it when peers come and go. A
  // keyframe made while mapping is hosted elsewhere goes to SystemEvents::keyframeCreated.
  void setHosting(Hosting hosting);
  Hosting hosting() const { return {hosting_mapping_.load(), hosting_loop_closing_.load()}; }
  // With mapping elsewhere: whether the remote mapper has caught up (keyframe decision), and a
  // bounded wait for it (offline runs).
  void setRemoteMapping(std::function<bool()> idle, std::function<void()> wait) {
    remote_idle_ = std::move(idle);
    remote_wait_ = std::move(wait);
  }
  enum class Module { Mapping, LoopClosing };
  // A keyframe from another node, already in `map`, for a module of this one.
  void submit(const std::shared_ptr<Map>& map, const std::shared_ptr<KeyFrame>& kf, Module module);
  // A map made on another node (or merged here from one); no-op when already known.
  void addMap(const std::shared_ptr<Map>& map);
  std::shared_ptr<Map> findMap(Id id) const;
  KeyframeDatabase& database() { return database_; }
  const std::vector<double>& scales() const { return extractor_.scales(); }
  // Before the first frame: the ids this node makes count on from `counter` (see ids.hpp).
  void startIdsAt(uint64_t counter) { ids_.advanceTo(counter); }
  const place::Vocabulary* vocabulary() const { return vocabulary_.get(); }
  // The end of a run: blocks until the queued keyframes of the hosted modules are done, then,
  // where loop closing is hosted, runs the final global BA of every map
  // (SlamSettings::final_global_ba_iterations) on the loop closing thread and waits for it.
  // Only the first call does the final BA. With SlamSettings::remeasure, the observations of
  // the keyframes made here are measured again first (remeasureOwnKeyframes), and the final BA
  // uses them with those received from other nodes (addRemeasurements).
  void drain();
  // Measures again every observation, in the live maps, of the keyframes whose images this node
  // kept (those it tracked), once: later calls return the first result. Holds each map's mutex
  // while it measures (the end of a run, tracking done). Empty without images.
  Remeasurements remeasureOwnKeyframes();
  // Observations another node measured again, for this node's final global BA.
  void addRemeasurements(const Remeasurements& r);
  // What this node has: measured here and received.
  Remeasurements remeasurements() const;
  struct RemeasureReport {
    RemeasureStats stats;  // of the pass over this node's own keyframes
    double ms = 0;         // its time
    double image_mb = 0;   // keyframe images kept for it
    size_t pyramids = 0;   // image pyramids it built (cached: a few dozen at a time)
    size_t own = 0;        // observations it measured again
    size_t total = 0;      // with those received
  };
  RemeasureReport remeasureReport() const;
  // Whether local mapping has no keyframe queued or in hand (after setHosting took mapping
  // away, what it still maps changes this node's maps only).
  bool mappingIdle() const;

  // Called on the tracking thread after each frame (set before the first): its record, its
  // pose when tracked, its keypoints and image. For a live view: it must return quickly.
  using FrameListener = std::function<void(const FrameRecord&, const Eigen::Isometry3d& T_cw,
                                           const std::vector<cv::KeyPoint>& keypoints, const cv::Mat& gray)>;
  void setFrameListener(FrameListener listener) { frame_listener_ = std::move(listener); }
  // Loops closed, maps merged and maps made so far, readable from any thread while it runs
  // (loopStats() is the loop closing thread's own until finish()).
  struct LiveCounts {
    int loops = 0, merges = 0, maps_made = 0;
  };
  LiveCounts liveCounts() const { return {loops_.load(), merges_.load(), maps_made_.load()}; }

  const std::vector<FrameRecord>& frames() const { return records_; }
  std::vector<std::shared_ptr<Map>> maps() const;
  int failures() const { return tracker_.failures(); }
  int relocalizedInKnownMap() const { return tracker_.relocalizedInKnownMap(); }
  int keyframesDeferred() const { return tracker_.keyframesDeferred(); }
  int keyframesMadeBusy() const { return tracker_.keyframesMadeBusy(); }
  const MappingStats& mappingStats() const { return mapper_.stats(); }
  const LoopStats& loopStats() const { return closer_.stats(); }
  // The map a frame's poses live in now (a merged map's frames live in the map it joined).
  Id currentMapId(Id map) const;
  // Maps that still hold keyframes (not merged into another).
  std::vector<std::shared_ptr<Map>> liveMaps() const;
  // Current camera-to-world pose of a tracked frame (through its reference keyframe, so later
  // optimizations of the keyframes move it too).
  Eigen::Isometry3d poseOf(const FrameRecord& r) const;
  // After finish(): poses every tracked frame again against the final map, by a pose-only
  // optimization from its own matches (those whose points survive), and keeps the result
  // relative to its reference keyframe. Frames with too few surviving matches keep their pose.
  // Returns how many frames were re-posed.
  int refineFrames();
  // The map holding the most keyframes (the one trajectories are reported in).
  std::shared_ptr<Map> largestMap() const;

 private:
  SlamSettings settings_;
  std::shared_ptr<const camera::CameraModel> camera_;
  IdGenerator ids_;
  features::OrbExtractor extractor_;
  std::shared_ptr<const place::Vocabulary> vocabulary_;
  KeyframeDatabase database_;
  Tracker tracker_;
  LocalMapper mapper_;
  LoopCloser closer_;
  mutable std::mutex atlas_mutex_;  // guards maps_ (the distribution layer adds maps)
  std::vector<std::shared_ptr<Map>> maps_;
  std::vector<FrameRecord> records_;
  SystemEvents* events_ = nullptr;
  std::atomic<bool> hosting_mapping_{true}, hosting_loop_closing_{true};
  std::function<bool()> remote_idle_;
  std::function<void()> remote_wait_;
  std::atomic<int> loop_jobs_pending_{0};
  std::atomic<bool> final_ba_done_{false};
  KeyframeImageStore images_;
  int images_kept_ = 0;  // tracking thread
  // Every 32 keyframes: the images of culled keyframes go. A long run at one place culls about as
  // many keyframes as it makes (a 30-minute soak of figure8 ended with 86), and each culled one's
  // image (361 KB at 752x480) stayed until the 512 MB budget was spent.
  void dropCulledKeyframeImages();
  // A keyframe tracking made while another node maps: into tracking's map, or the map that one
  // has been merged into since. Returns the map it went into.
  std::shared_ptr<Map> insertOwnKeyframe(const std::shared_ptr<KeyFrame>& kf);
  // The image of the current initialization attempt's first frame (tracking thread only): a new
  // map's first keyframe is made of it, frames after it was seen.
  cv::Mat initialization_image_;
  mutable std::mutex remeasured_mutex_;  // guards the four below
  Remeasurements remeasured_;
  bool remeasured_own_ = false;
  Remeasurements own_remeasured_;
  RemeasureReport remeasure_report_;

  struct MappingJob {
    std::shared_ptr<Map> map;
    std::shared_ptr<KeyFrame> keyframe;  // for loop closing, none: the map's final global BA
  };
  void mappingLoop();
  // What local mapping calls before its local BA: the keyframeTriangulated event, if anyone listens.
  std::function<void()> beforeBa(const std::shared_ptr<Map>& map, const std::shared_ptr<KeyFrame>& kf) const;
  void loopLoop();
  // Loop closing on one keyframe, then its counts published to liveCounts().
  void closeLoops(const std::shared_ptr<Map>& map, const std::shared_ptr<KeyFrame>& kf);
  FrameListener frame_listener_;
  std::atomic<int> loops_{0}, merges_{0}, maps_made_{0};
  // The final global BA of `map`, with the observations measured again so far.
  void finalBundleAdjustment(Map& map);
  void waitForMapping();
  Mode mode_;
  BlockingQueue<MappingJob> jobs_;
  std::atomic<bool> mapping_busy_{false};
  mutable std::mutex idle_mutex_;
  std::condition_variable idle_cv_;
  size_t jobs_pushed_ = 0, jobs_done_ = 0;  // guarded by idle_mutex_
  std::atomic<bool> abort_ba_{false};
  std::thread mapping_thread_;
  BlockingQueue<MappingJob> loop_jobs_;
  std::thread loop_thread_;
  std::atomic<int> stale_keyframes_{0};  // queued for a map that was merged meanwhile
  std::atomic<Map*> active_map_{nullptr};  // tracking's map, for the loop closer
};

}  // namespace hiveslam::core
