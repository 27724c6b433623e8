#pragma once
// Every threshold of the SLAM core in one plain struct with its defaults; the settings file's
// `slam:` section overrides any of them (io/slam_settings_io reads it).
#include <cstdint>
#include <string>

#include "core/features/orb_extractor.hpp"

namespace hiveslam::core {

struct SlamSettings {
  features::OrbOptions orb;
  // Initialization
  int init_min_matches = 100;
  double init_min_parallax_deg = 1.0;
  int init_min_points = 50;
  // Tracking
  double search_radius_last_frame = 15.0;  // pixels at level 0
  int min_matches_last_frame = 20;
  int min_inliers_tracking = 30;
  int min_inliers_after_relocalization = 50;
  int local_keyframes = 10;                // covisible keyframes around the tracked points
  // Keyframe decision (the paper's rule: >= 2 frames since the last keyframe, ratio 0.8)
  int keyframe_min_frames = 2;
  int keyframe_max_frames = 20;            // a keyframe at least this often (about 1 s)
  double keyframe_ratio = 0.8;             // tracked / reference keyframe's points below this
  // Below this share a due keyframe is made even while mapping is busy: tracking is about to
  // run out of points, and waiting for mapping would lose the map. Mapping's acknowledgement
  // takes a round trip over the network when it runs on another node: over a lossy link a young
  // map's keyframes waited 20 frames for it and TR lost 3 of its first maps in 24 runs.
  // On the standard suite no keyframe waits that long (the lowest share seen is 0.67).
  double keyframe_weak_ratio = 0.5;
  // Past this many degrees of turn since the last keyframe a keyframe is due, and made even while
  // mapping is busy (0: no such rule). The keyframe chain carries a monocular map's scale through
  // a fast turn, and a gap there bends the map (core/mapping/keyframe_gap.hpp). With this and the
  // culling limit below at 5 degrees, 3-node real-time sweep runs keep about 12 more keyframes
  // (102 against 90) and lost their tail in 8 interleaved pairs, and bench64 held every rule; at
  // 10 degrees they kept it. Off for now: the standalone system's CPU on figure8 rose 65%, and
  // SlamSystem.ClosesTheLoopOfARenderedLoop no longer saw loop closing halve the revisit gap. Set 5 to use it.
  double keyframe_turn_deg = 0.0;
  int keyframe_min_inliers = 15;
  // Loss handling: a new map after this many lost frames once the map is past its first
  // keyframes (the paper's wait for the initial keyframes to be optimized).
  int lost_frames_before_new_map = 20;
  // A lost tracker, and one about to start a new map, relocalizes in every map of the atlas,
  // not only in the one it lost: a revisit continues the map made there.
  bool relocalize_in_every_map = true;
  // Local mapping
  // Neighbours searched for new points (and, below, for duplicates). ORB-SLAM's monocular value
  // is 20; 20 here helped the sequential runs (median ATE at six feature budgets: figure8 10.6 ->
  // 9.4 mm, sweep 10.0 -> 6.2) but not the real-time bench (3-node sweep median 6.1 -> 12.7 mm).
  int triangulation_neighbours = 10;
  double triangulation_max_cos_parallax = 0.9998;  // new points need a wider angle (1.15 deg)
  // Candidates for new points only under the same vocabulary node (ORB-SLAM's way) instead of
  // along the whole epipolar band. Sequential runs at twelve feature budgets: sweep median 8.9
  // -> 5.2 mm, blackout 9.4 -> 6.0, CPU -25%; but about 12% fewer points, and in the real-time
  // bench the 3-node outlier rule failed on three sequences (one TR lost figure8's fast turn,
  // short of points) where it had held on all four: off until two benches say otherwise.
  bool triangulation_by_vocabulary = false;
  // A new point's two keypoints must be closer in descriptor than this share of the nearer of
  // their look-alikes, the most similar other keypoint in either's own image
  // (common/look_alikes.hpp), where either is a weak corner (features::isWeakCorner); 0: no
  // such check. Keypoints on smooth shading or in a repeated pattern have twins a few bits
  // away, and a match no better than the twin is a guess. Real time, 5 runs each: the realistic
  // suite's median ATE 4.5 / 4.8 / 10.3 / 5.4% of the path against 5.2 / 7.9 / 10.8 / 8.4%
  // without; at 1.0, 5.0 / 5.6 / 4.9 / 3.1%, but KITTI 07 0.42-0.44% against 0.39-0.41%, where
  // 1.2 gives 0.38-0.39% (docs/BENCHMARKS.md).
  double triangulation_look_alike_ratio = 1.2;
  int fusion_neighbours = 10;
  int local_ba_iterations = 10;
  // Keyframes that may wait for local mapping while it works on an earlier one (0: a keyframe is
  // made only when mapping is idle). A keyframe queued so cuts the running local BA short, as
  // ORB-SLAM's local mapping does. At 1, real-time runs of the realistic suite deferred a
  // keyframe on at most 0.3% of frames instead of 7-22% and tracked more frames in fewer maps,
  // for 15-40% more CPU there; the standard suite's bench held the same rules as at 0 in the
  // same sitting, with no keyframe deferred (docs/BENCHMARKS.md).
  int keyframe_queue = 1;
  // A keyframe goes when this share of its points is seen by 3 others at the same or a finer
  // scale (ORB-SLAM's 0.9). 0.95 keeps a third more keyframes and cut the standalone system's
  // median ATE (sequential, perturbed: figure8 10.6 -> 7.6 mm, sweep 10.0 -> 5.1; realtime
  // bench: all four sequences), but the 3-node system got worse with it (sweep median 5.2 mm
  // over 7 runs at 0.9, about 10 over 8 at 0.95).
  double redundant_keyframe_ratio = 0.9;
  // A redundant keyframe stays when its neighbours in time would be more than this many degrees
  // apart in viewing direction without it (0: no limit; core/mapping/keyframe_gap.hpp, and
  // keyframe_turn_deg above).
  double keyframe_culling_max_angle_deg = 0.0;
  // Loop closing and map merging
  bool loop_closing = true;
  std::string vocabulary;              // file; empty: the one shipped in data/vocabulary
  int loop_min_keyframes = 12;         // a map this small is not searched for loops
  int loop_consistency = 3;            // consecutive keyframes that must agree on a place
  int loop_min_bow_matches = 20;       // keyframe pair matches before Sim3 RANSAC
  int loop_min_sim3_inliers = 20;
  double loop_min_inlier_ratio = 0.5;  // of the matches after guided matching
  int loop_min_total_matches = 40;     // Sim3 inliers + matches of the place's points
  // A loop within one map corrects one walk's drift: a Sim3 that changes the scale by more than
  // this either way is refused as degenerate (a lossy-link 3-node run accepted one of 0.00065
  // from 234 matches and ended at 12.8% of the path). Merges of two maps are not bounded.
  double loop_max_scale_change = 10.0;
  int essential_graph_min_weight = 100;  // covisibility edges kept in the essential graph
  int essential_graph_iterations = 20;
  int global_ba_iterations = 10;
  // Global BA judges residuals against the noise the map has: its observations' sigma is this
  // many times the noise read off the median residual (at most one pixel per level; 0: one
  // pixel per level, as local BA). Sub-pixel corners measure to about 0.16 px per level, but
  // about a tenth of the observations sit 0.6-2.4 px off under the true geometry too (corners
  // whose refined position moves with the view): inside a one-pixel Huber kernel they were
  // weighed in full. Six sequential sweep maps, the final BA again: keyframe ATE 9.1 5.8 3.4
  // 4.6 2.4 8.5 -> 3.9 4.1 2.3 1.2 2.2 3.5 mm.
  double global_ba_noise_factor = 1.5;
  // With the noise factor: a global BA of a map no loop or merge has just moved judges its
  // outliers on the residuals it starts from and solves once without them, instead of solving
  // with them, judging, and solving again (BaOptions::Outliers). A third of the time (sequential
  // runs at six feature budgets: global BA 6.1-7.4 s -> 2.1-3.0 s on sweep, 16-18 -> 6-8 on
  // bigloop; CPU -5 to -17%) and about the same ATE on figure8 and bigloop, but the medians
  // of sweep 3.7 -> 4.5 mm and blackout 3.0 -> 3.4. The start leaves out 5-10% more
  // observations than a first round does, as many among the newest keyframes; why that costs
  // sweep is not traced. Off until a bench says otherwise.
  bool global_ba_outliers_from_start = false;
  // A global BA each time a map has grown by this many keyframes, loop or not (0: only after
  // loops and merges). Local BA holds its border where earlier windows left it; this lets
  // every observation weigh in again. Sequential runs at six feature budgets: figure8 median
  // 9.9 -> 5.7 mm, worst 24.0 -> 6.3; sweep 10.0 -> 7.5.
  int global_ba_every_keyframes = 10;
  // At the end of a run (SlamSystem::drain), once every keyframe is mapped: one more global BA
  // of each map with this many iterations (0: none), on whichever node hosts loop closing. In
  // real time the map ends where its last local BAs left it, up to 10 keyframes after the last
  // global BA; sequential runs end converged and are unchanged (figure8 at six feature budgets:
  // 5.2-6.3 -> 5.0-6.1 mm), real-time ones gain (figure8: 9.1 9.8 8.1 -> 5.8 6.9 7.6 mm).
  int final_global_ba_iterations = 50;
  // Before that final BA: every observation of the maps measured again by patch alignment
  // against its point's first view (optim/remeasure_observations.hpp), by the node that made the
  // keyframes and holds their images, and the final BA runs loose (a pixel per level, nothing
  // left out) before its usual noise-scaled solve. Re-detected corners move with the view by a
  // few tenths of a pixel and bend sweep's maps through the turn; on saved maps this halved the
  // scale step's spread (0.21% -> 0.10%) and the keyframe ATE.
  bool remeasure = true;
  // The keyframe images kept for it (level 0, 361 KB each at 752x480); past it, none more.
  int remeasure_image_budget_mb = 512;
  // At the end of a run (SlamSystem::refineFrames): each tracked frame is posed again against
  // the final map from the matches it was tracked with. A frame is otherwise held relative to
  // its reference keyframe as it was when tracked, and keeps the map's error of that moment.
  // Costs about 24 bytes per match kept (some 6 KB per frame).
  bool refine_frames = true;
  // Matches are kept for the last this many frames only (0: every frame): a long run's memory
  // would grow by them without end (a 3-node soak's TR by 12.5 MB a minute at 20 Hz, figure8's
  // 10 KB a frame). Older frames stay as tracked, relative to their reference keyframe.
  int refine_frames_window = 3000;
  // Determinism: RANSAC seed
  uint64_t seed = 1;
};

}  // namespace hiveslam::core
