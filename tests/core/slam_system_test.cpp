// The whole sequential pipeline on a short rendered sequence: tracks, stays accurate, and the
// same input gives the same trajectory.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <map>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "core/camera/pinhole_radtan.hpp"
#include "core/loop/map_correction.hpp"
#include "core/mapping/keyframe_gap.hpp"
#include "core/system/slam_system.hpp"
#include "eval/similarity.hpp"
#include "eval/trajectory_error.hpp"
#include "synth/sequence.hpp"

namespace hiveslam::core {
namespace {

struct SlamRun {
  io::Trajectory estimate, truth;
  int frames = 0, tracked = 0;
  int loops = 0, merges = 0, global_bas = 0;
  size_t live_maps = 0, keyframes = 0;
  int keyframes_deferred = 0;
  double widest_keyframe_step_deg = 0;  // between keyframes next in time, the largest map's
};

std::shared_ptr<const place::Vocabulary> shippedVocabulary() {
  static const auto voc = std::make_shared<const place::Vocabulary>(
      place::Vocabulary::load(std::string(HIVESLAM_SOURCE_DIR) + "/data/vocabulary/orb_k10_l4.bin"));
  return voc;
}

// Frames [first, first + count) of a sequence of `total` frames (its speed set by `total`).
SlamRun runSequence(const std::string& trajectory, int total, int first, int count, uint64_t seed, SlamSystem::Mode mode,
                    std::shared_ptr<const place::Vocabulary> vocabulary = nullptr, const SlamSettings& settings = {},
                    SystemEvents* events = nullptr) {
  synth::SequenceOptions o;
  o.trajectory = trajectory;
  o.frames = total;
  o.seed = seed;
  const auto model = synth::buildSequence(o);
  const synth::RayTable rays(model.lens);
  auto camera = std::make_shared<camera::PinholeRadTan>(model.lens.width, model.lens.height, model.lens.fx,
                                                        model.lens.fy, model.lens.cx, model.lens.cy);
  SlamSystem slam(settings, camera, mode, std::move(vocabulary));
  slam.setEvents(events);
  SlamRun run;
  // Rendering costs as much as tracking: tests that run one sequence twice render it once.
  static std::map<std::string, cv::Mat> rendered;
  for (int f = first; f < first + count; ++f) {
    const std::string key = trajectory + "/" + std::to_string(total) + "/" + std::to_string(seed) + "/" + std::to_string(f);
    auto it = rendered.find(key);
    if (it == rendered.end()) it = rendered.emplace(key, model.renderImage(f, rays)).first;
    slam.process(it->second, model.stamp(f));
    run.truth.add(model.stamp(f), model.pose(f));
  }
  slam.finish();
  const auto map = slam.largestMap();
  for (const auto& r : slam.frames()) {
    ++run.frames;
    if (!r.tracked) continue;
    ++run.tracked;
    if (slam.currentMapId(r.map) == map->id) run.estimate.add(r.timestamp, slam.poseOf(r));
  }
  run.loops = slam.loopStats().loops;
  run.merges = slam.loopStats().merges;
  run.global_bas = slam.loopStats().global_bas;
  run.live_maps = slam.liveMaps().size();
  run.keyframes_deferred = slam.keyframesDeferred();
  {
    std::lock_guard lock(map->mutex);
    run.keyframes = map->keyframes.size();
    std::vector<const KeyFrame*> chain;
    for (const auto& [id, kf] : map->keyframes) chain.push_back(kf.get());
    std::sort(chain.begin(), chain.end(), [](auto* a, auto* b) { return a->frame.timestamp < b->frame.timestamp; });
    for (size_t i = 1; i < chain.size(); ++i)
      run.widest_keyframe_step_deg =
          std::max(run.widest_keyframe_step_deg, viewAngleDegrees(chain[i - 1]->T_cw.linear(), chain[i]->T_cw.linear()));
  }
  return run;
}

TEST(SlamSystem, TracksARenderedLoopAccurately) {
  const SlamRun run = runSequence("loop", 400, 0, 250, 1, SlamSystem::Mode::Sequential);
  EXPECT_GE(run.tracked, 0.9 * run.frames);
  const auto ate = eval::computeAte(run.truth, run.estimate);
  EXPECT_LT(ate.stats.rmse, 0.01 * ate.reference_length) << ate.stats.rmse << " m over " << ate.reference_length;
}

// Local mapping times each stage of each keyframe, so that a run's report says where its time
// goes (`mapping.ms_per_keyframe`).
TEST(SlamSystem, LocalMappingTimesEachStage) {
  synth::SequenceOptions o;
  o.trajectory = "loop";
  o.frames = 400;
  const auto model = synth::buildSequence(o);
  const synth::RayTable rays(model.lens);
  auto camera = std::make_shared<camera::PinholeRadTan>(model.lens.width, model.lens.height, model.lens.fx,
                                                        model.lens.fy, model.lens.cx, model.lens.cy);
  SlamSystem slam({}, camera, SlamSystem::Mode::Sequential);
  for (int f = 0; f < 60; ++f) slam.process(model.renderImage(f, rays), model.stamp(f));
  slam.finish();
  const MappingStats& stats = slam.mappingStats();
  ASSERT_GE(stats.keyframes_processed, 3);
  const MappingStageMs& ms = stats.ms;
  for (double stage : {ms.insert, ms.triangulate, ms.fuse, ms.local_ba_setup, ms.local_ba, ms.cull_keyframes})
    EXPECT_GT(stage, 0.0);
  EXPECT_NEAR(ms.total, ms.insert + ms.cull_points + ms.triangulate + ms.fuse + ms.local_ba_setup + ms.local_ba + ms.cull_keyframes,
              1e-6 * ms.total);
  EXPECT_GE(ms.max_total, ms.total / stats.keyframes_processed);
  EXPECT_LE(ms.max_total, ms.total);
}

// Threaded: tracking on this thread, local mapping on its own. Thread timing varies with the
// machine's load, so the bar is lower than the deterministic run's; TSan runs this test too.
TEST(SlamSystem, ThreadedModeTracks) {
  const SlamRun run = runSequence("loop", 400, 0, 250, 1, SlamSystem::Mode::Offline);
  EXPECT_GE(run.tracked, 0.8 * run.frames);
  const auto ate = eval::computeAte(run.truth, run.estimate);
  EXPECT_LT(ate.stats.rmse, 0.02 * ate.reference_length) << ate.stats.rmse << " m over " << ate.reference_length;
}

// Where the path comes back to its start: how far the estimate's displacement between the
// start and the revisit is from the true one, after aligning the whole trajectory. Open loop,
// this is the drift accumulated over the lap; a closed loop takes it out.
double revisitGap(const eval::AteResult& ate) {
  const auto& ref = ate.pair.ref.poses;
  const auto& est = ate.pair.est.poses;
  size_t back = ref.size() - 1;
  for (size_t j = ref.size() * 3 / 4; j < ref.size(); ++j)
    if ((ref[j].translation() - ref[0].translation()).norm() < (ref[back].translation() - ref[0].translation()).norm()) back = j;
  return ((est[back].translation() - est[0].translation()) - (ref[back].translation() - ref[0].translation())).norm();
}

// The whole loop at twice the suite's speed: the revisit of the start is recognized, the loop
// closed, and the drift the open-loop run carries back to the start is taken out.
TEST(SlamSystem, ClosesTheLoopOfARenderedLoop) {
  const SlamRun open = runSequence("loop", 500, 0, 500, 1, SlamSystem::Mode::Sequential);
  const SlamRun closed = runSequence("loop", 500, 0, 500, 1, SlamSystem::Mode::Sequential, shippedVocabulary());
  EXPECT_EQ(open.loops, 0);
  EXPECT_GE(closed.loops, 1);
  const auto ate_open = eval::computeAte(open.truth, open.estimate);
  const auto ate_closed = eval::computeAte(closed.truth, closed.estimate);
  EXPECT_LT(ate_closed.stats.rmse, 0.01 * ate_closed.reference_length);
  // Over the whole 500-frame lap both runs are near 4 mm, and which is lower is a draw (4.1
  // against 4.25 mm, and 4.45 against 4.25 once global BA judged by the map's noise). At the
  // revisit, the open run's drift stands apart: 12.3 mm against 3.5-3.9 closed.
  EXPECT_LT(revisitGap(ate_closed), 0.5 * revisitGap(ate_open))
      << revisitGap(ate_closed) << " vs " << revisitGap(ate_open) << " (ATE " << ate_closed.stats.rmse << " vs "
      << ate_open.stats.rmse << ")";
}

// A loop whose Sim3 changes the scale by more than loop_max_scale_change either way is
// refused. At 1, any change of scale at all is: the lap's loop is not closed.
TEST(SlamSystem, ALoopBeyondTheScaleBoundIsRefused) {
  SlamSettings settings;
  settings.loop_max_scale_change = 1.0;
  const SlamRun run = runSequence("loop", 500, 0, 500, 1, SlamSystem::Mode::Sequential, shippedVocabulary(), settings);
  EXPECT_EQ(run.loops, 0);
}

// Tracking is lost in the blank frames and a new map starts after them; recognizing the old
// map's places welds the two back into one map with every tracked frame in it.
TEST(SlamSystem, MergesTheMapsAcrossABlankSegment) {
  const SlamRun run = runSequence("blackout", 500, 0, 500, 2, SlamSystem::Mode::Sequential, shippedVocabulary());
  EXPECT_GE(run.merges, 1);
  EXPECT_EQ(run.live_maps, 1u);
  EXPECT_EQ(static_cast<int>(run.estimate.size()), run.tracked);
  const auto ate = eval::computeAte(run.truth, run.estimate);
  EXPECT_LT(ate.stats.rmse, 0.01 * ate.reference_length) << ate.stats.rmse << " m over " << ate.reference_length;
}

// Along one wall and back along the other: every place looks alike (the same texture statistics
// everywhere) but none is visited twice, so nothing may be closed or merged. With
// global_ba_every_keyframes set, the map still gets a global BA each time it has grown by that
// many keyframes (culled ones counted out).
TEST(SlamSystem, ClosesNoLoopOnASequenceThatNeverRevisits) {
  SlamSettings settings;
  const int every = settings.global_ba_every_keyframes = 10;
  const SlamRun run = runSequence("sweep", 400, 0, 400, 3, SlamSystem::Mode::Sequential, shippedVocabulary(), settings);
  EXPECT_GE(run.tracked, 0.9 * run.frames);
  EXPECT_EQ(run.loops, 0);
  EXPECT_EQ(run.merges, 0);
  EXPECT_GE(run.global_bas, static_cast<int>(run.keyframes) / every - 1) << run.keyframes << " keyframes";
  EXPECT_LE(run.global_bas, static_cast<int>(run.keyframes) / every + 1) << run.keyframes << " keyframes";
}

// The sweep sequence (600 frames, seed 4), its ray table and an ideal pinhole camera.
struct Sweep {
  static synth::SequenceModel build() {
    synth::SequenceOptions o;
    o.trajectory = "sweep";
    o.frames = 600;
    o.seed = 4;
    return synth::buildSequence(o);
  }
  synth::SequenceModel model = build();
  synth::RayTable rays{model.lens};
  std::shared_ptr<camera::PinholeRadTan> camera = std::make_shared<camera::PinholeRadTan>(
      model.lens.width, model.lens.height, model.lens.fx, model.lens.fy, model.lens.cx, model.lens.cy);
};

// Kidnapped: after 120 frames the camera jumps back to where it was at frame 40. Tracking must
// lose the pose, find the place again through the keyframe database and go on in the same map.
TEST(SlamSystem, RelocalizesAfterAJumpBackWithoutLoopClosing) {
  const Sweep sweep;
  const auto& model = sweep.model;
  const auto& rays = sweep.rays;
  const auto& camera = sweep.camera;
  SlamSettings settings;
  settings.loop_closing = false;
  SlamSystem slam(settings, camera, SlamSystem::Mode::Sequential, shippedVocabulary());
  double t = 0;
  for (int f = 0; f < 120; ++f) slam.process(model.renderImage(f, rays), t += 0.05);
  ASSERT_TRUE(slam.frames().back().tracked);
  int tracked_after_jump = 0;
  for (int f = 40; f < 60; ++f) tracked_after_jump += slam.process(model.renderImage(f, rays), t += 0.05).tracked;
  slam.finish();
  EXPECT_GE(tracked_after_jump, 15);
  EXPECT_EQ(slam.liveMaps().size(), 1u);
  EXPECT_GE(slam.failures(), 1);
}

// Lost in a blank stretch, the camera starts a second map elsewhere, loses it in another blank
// stretch and comes back to the first place: tracking goes on in the first map, found through
// the keyframe database over every map, instead of starting a third (phone_room_droidcam's door
// corner, seen again after two maps, was a new map each time).
TEST(SlamSystem, ARevisitAfterANewMapRelocalizesInTheOldMap) {
  const Sweep sweep;
  SlamSettings settings;
  settings.loop_closing = false;  // no merge: only relocalization may join the revisit
  SlamSystem slam(settings, sweep.camera, SlamSystem::Mode::Sequential, shippedVocabulary());
  const cv::Mat blank(sweep.model.lens.height, sweep.model.lens.width, CV_8UC1, cv::Scalar(128));
  double t = 0;
  for (int f = 0; f < 100; ++f) slam.process(sweep.model.renderImage(f, sweep.rays), t += 0.05);
  ASSERT_TRUE(slam.frames().back().tracked);
  const Id first_map = slam.frames().back().map;
  for (int f = 0; f < settings.lost_frames_before_new_map + 5; ++f) slam.process(blank, t += 0.05);
  for (int f = 450; f < 540; ++f) slam.process(sweep.model.renderImage(f, sweep.rays), t += 0.05);
  ASSERT_TRUE(slam.frames().back().tracked);
  ASSERT_NE(slam.frames().back().map, first_map) << "the second stretch must make a map of its own";
  for (int f = 0; f < settings.lost_frames_before_new_map + 5; ++f) slam.process(blank, t += 0.05);
  int in_first_map = 0;
  for (int f = 30; f < 60; ++f) in_first_map += slam.process(sweep.model.renderImage(f, sweep.rays), t += 0.05).map == first_map;
  slam.finish();
  EXPECT_GE(slam.relocalizedInKnownMap(), 1);
  EXPECT_GE(in_first_map, 25);
  EXPECT_EQ(slam.liveMaps().size(), 2u);
}

// Another node merges the map tracking is in into another one (at TR, LC's merge of TR's old map
// into its newer one came right after TR had relocalized in the old one). Tracking follows the
// map into the merged one and goes on in its frame: before, it kept tracking in the emptied map
// and its next keyframe went there, seen by points of the merged map (an atlas with dangling
// observations, and a keyframe TR alone lacked).
TEST(SlamSystem, TrackingFollowsItsMapIntoTheMapItWasMergedInto) {
  const Sweep sweep;
  SlamSettings settings;
  settings.loop_closing = false;  // the merge comes from outside
  SlamSystem slam(settings, sweep.camera, SlamSystem::Mode::Sequential, shippedVocabulary());
  const cv::Mat blank(sweep.model.lens.height, sweep.model.lens.width, CV_8UC1, cv::Scalar(128));
  double t = 0;
  for (int f = 0; f < 100; ++f) slam.process(sweep.model.renderImage(f, sweep.rays), t += 0.05);
  const Id first_map = slam.frames().back().map;
  for (int f = 0; f < settings.lost_frames_before_new_map + 5; ++f) slam.process(blank, t += 0.05);
  for (int f = 450; f < 540; ++f) slam.process(sweep.model.renderImage(f, sweep.rays), t += 0.05);
  const Id second_map = slam.frames().back().map;
  ASSERT_NE(second_map, first_map);
  for (int f = 0; f < settings.lost_frames_before_new_map + 5; ++f) slam.process(blank, t += 0.05);
  for (int f = 30; f < 45; ++f) slam.process(sweep.model.renderImage(f, sweep.rays), t += 0.05);
  ASSERT_TRUE(slam.frames().back().tracked);
  ASSERT_EQ(slam.frames().back().map, first_map);
  const Eigen::Vector3d center_before = slam.poseOf(slam.frames().back()).translation();

  // The merge as a node applies one: the first map's contents move into the second by S.
  const Sim3 S(Eigen::Quaterniond(Eigen::AngleAxisd(0.5, Eigen::Vector3d::UnitY())), {3.0, -1.0, 2.0}, 1.5);
  const auto first = slam.findMap(first_map), second = slam.findMap(second_map);
  {
    std::scoped_lock both(first->mutex, second->mutex);
    PoseCorrection c;
    for (const auto& [id, kf] : first->keyframes) {
      c.before[kf.get()] = Sim3(kf->T_cw);
      c.after[kf.get()] = Sim3(Eigen::Quaterniond::Identity(), Eigen::Vector3d::Zero(), S.s) * Sim3(kf->T_cw) * S.inverse();
    }
    for (const auto& [id, p] : first->points) c.points[p.get()] = S * p->position;
    second->absorb(*first);
    slam.database().moveMap(first.get(), second.get());
    applyCorrection(*second, c, slam.scales());
  }

  int tracked = 0, in_second = 0;
  for (int f = 45; f < 75; ++f) {
    const auto& r = slam.process(sweep.model.renderImage(f, sweep.rays), t += 0.05);
    tracked += r.tracked;
    in_second += r.tracked && slam.currentMapId(r.map) == second_map && r.map == second_map;
    if (f == 45 && r.tracked) {
      const Eigen::Vector3d center_after = slam.poseOf(r).translation();
      EXPECT_LT((S.inverse() * center_after - center_before).norm(), 0.05) << "the first frame after the merge, in its frame";
    }
  }
  slam.finish();
  EXPECT_GE(tracked, 27);
  EXPECT_EQ(in_second, tracked);
  EXPECT_TRUE(first->keyframes.empty()) << "a keyframe went into the merged-away map";
  // Every observation in the merged map is of one of its keyframes.
  std::lock_guard lock(second->mutex);
  for (const auto& [id, p] : second->points)
    for (const auto& [kf, i] : p->observations) ASSERT_TRUE(second->keyframes.count(kf->id)) << "point " << id;
}

// A long run keeps the matches for refineFrames of its last refine_frames_window frames only: a
// 30-minute soak's TR grew by 12.5 MB a minute with all of them.
TEST(SlamSystem, MatchesAreKeptForTheLastFramesOnly) {
  const Sweep sweep;
  SlamSettings settings;
  settings.refine_frames_window = 40;
  SlamSystem slam(settings, sweep.camera, SlamSystem::Mode::Sequential);
  double t = 0;
  for (int f = 100; f < 200; ++f) slam.process(sweep.model.renderImage(f, sweep.rays), t += 0.05);
  const auto& frames = slam.frames();
  ASSERT_EQ(frames.size(), 100u);
  for (size_t i = 0; i < frames.size(); ++i) {
    if (i < frames.size() - 40) {
      EXPECT_TRUE(frames[i].observations.empty()) << i;
    } else if (frames[i].tracked) {
      EXPECT_FALSE(frames[i].observations.empty()) << i;
    }
  }
  slam.finish();
}

// The stricter inlier check after a relocalization (a pose found by PnP against a place may be
// wrong) is not for a map just initialized. A run that starts in motion initializes within its
// first frames; with that check out of reach, not one of them may be dropped as lost. (It was
// applied to the first 20 frames of every run: on KITTI 06, a car driving forward, three young
// maps were dropped with 43-49 inliers, against 50.)
TEST(SlamSystem, AFreshMapIsNotHeldToTheCheckThatFollowsARelocalization) {
  const Sweep sweep;
  SlamSettings settings;
  settings.min_inliers_after_relocalization = 1000000;
  SlamSystem slam(settings, sweep.camera, SlamSystem::Mode::Sequential, shippedVocabulary());
  double t = 0;
  for (int f = 100; f < 140; ++f) slam.process(sweep.model.renderImage(f, sweep.rays), t += 0.05);
  slam.finish();
  int first_tracked = -1, tracked = 0;
  for (size_t i = 0; i < slam.frames().size(); ++i)
    if (slam.frames()[i].tracked) {
      if (first_tracked < 0) first_tracked = static_cast<int>(i);
      ++tracked;
    }
  ASSERT_GE(first_tracked, 0);
  ASSERT_LT(first_tracked, 10) << "initialized too late to test the first 20 frames";
  EXPECT_EQ(tracked, 40 - first_tracked);
  EXPECT_EQ(slam.failures(), 0);
  EXPECT_EQ(slam.liveMaps().size(), 1u);
}

// The end of a run (drain) brings one last global BA of each map, on the loop closing thread once
// every keyframe is mapped; a second drain brings none, and the setting at 0 switches it off.
TEST(SlamSystem, TheEndOfARunBringsOneFinalGlobalBa) {
  const Sweep sweep;
  std::vector<cv::Mat> images;
  for (int f = 0; f < 100; ++f) images.push_back(sweep.model.renderImage(f, sweep.rays));
  for (const int iterations : {50, 0}) {
    SlamSettings settings;
    settings.global_ba_every_keyframes = 0;  // so that every global BA seen here is the final one
    settings.final_global_ba_iterations = iterations;
    SlamSystem slam(settings, sweep.camera, SlamSystem::Mode::Offline, shippedVocabulary());
    double t = 0;
    for (const auto& image : images) slam.process(image, t += 0.05);
    ASSERT_EQ(slam.liveMaps().size(), 1u);
    slam.drain();
    EXPECT_EQ(slam.loopStats().global_bas, iterations > 0 ? 1 : 0) << iterations << " iterations";
    slam.drain();
    EXPECT_EQ(slam.loopStats().global_bas, iterations > 0 ? 1 : 0) << "after a second drain";
    slam.finish();
  }
}

// The map's first keyframe is made of a frame seen before initialization succeeded, and anchors
// every point of the initial map: its image must be kept like every other keyframe's, or none of
// those points' observations is measured again (when it was not kept, 7% of sweep's observations, all near
// the start of the run, stayed as found).
TEST(SlamSystem, TheFirstKeyframesPointsAreMeasuredAgainToo) {
  const Sweep sweep;
  SlamSystem slam(SlamSettings{}, sweep.camera, SlamSystem::Mode::Sequential, shippedVocabulary());
  for (int f = 0; f < 80; ++f) slam.process(sweep.model.renderImage(f, sweep.rays), sweep.model.stamp(f));
  slam.drain();  // the re-measurement, before the final BA
  slam.finish();
  const auto map = slam.largestMap();
  const Remeasurements measured = slam.remeasurements();
  std::lock_guard lock(map->mutex);
  const KeyFrame* origin = map->origin;
  ASSERT_NE(origin, nullptr);
  size_t observations = 0, found = 0;
  for (const auto& p : origin->points) {
    if (!p || p->bad || p->observations.begin()->first != origin) continue;  // anchored elsewhere
    for (const auto& [kf, keypoint] : p->observations) {
      if (kf == origin) continue;
      ++observations;
      const auto it = measured.find(kf->id);
      if (it == measured.end()) continue;
      for (const Remeasurement& r : it->second)
        found += r.keypoint == static_cast<uint32_t>(keypoint) && r.point == p->id && r.anchor_keyframe == origin->id;
    }
  }
  ASSERT_GT(observations, 500u);
  // Some fail to align (too little texture, a shift past a pixel): about a seventh of all.
  EXPECT_GT(found, 0.7 * static_cast<double>(observations)) << found << " of " << observations;
}

// A frame is held relative to its reference keyframe as it was tracked. When the map moves in a
// way that relative pose does not follow (here every point and keyframe scaled by 1.5 about the
// origin, the keyframes' scale bookkeeping left alone), the frame is off until refineFrames poses
// it again from its own matches against the final map.
TEST(SlamSystem, RefinedFramesFollowTheMapTheyWereTrackedIn) {
  const Sweep sweep;
  std::vector<cv::Mat> images;
  io::Trajectory truth;
  for (int f = 0; f < 120; ++f) {
    images.push_back(sweep.model.renderImage(f, sweep.rays));
    truth.add(sweep.model.stamp(f), sweep.model.pose(f));
  }
  for (const bool refine : {true, false}) {
    SlamSettings settings;
    settings.refine_frames = refine;
    SlamSystem slam(settings, sweep.camera, SlamSystem::Mode::Sequential);
    for (int f = 0; f < 120; ++f) slam.process(images[static_cast<size_t>(f)], sweep.model.stamp(f));
    slam.finish();
    const auto map = slam.largestMap();
    ASSERT_TRUE(map);
    int tracked = 0;
    const auto ate = [&] {
      io::Trajectory estimate;
      tracked = 0;
      for (const auto& r : slam.frames())
        if (r.tracked && slam.currentMapId(r.map) == map->id) {
          estimate.add(r.timestamp, slam.poseOf(r));
          ++tracked;
        }
      return eval::computeAte(truth, estimate).stats.rmse;
    };
    const double before = ate();
    ASSERT_GT(tracked, 90);
    {
      std::lock_guard lock(map->mutex);
      for (auto& [id, p] : map->points) p->position *= 1.5;
      for (auto& [id, kf] : map->keyframes) kf->T_cw.translation() *= 1.5;
    }
    const double moved = ate();
    const int refined = slam.refineFrames();
    const double after = ate();
    if (!refine) {
      EXPECT_EQ(refined, 0);
      continue;
    }
    EXPECT_GE(refined, 0.95 * tracked);
    EXPECT_GT(moved, 3 * before) << "the scaled map must leave the frames' relative poses behind";
    EXPECT_LT(after, 1.1 * before + 0.0005) << before << " m before, " << moved << " m moved";
  }
}

TEST(SlamSystem, SequentialModeIsDeterministic) {
  const SlamRun a = runSequence("sweep", 600, 100, 80, 4, SlamSystem::Mode::Sequential), b = runSequence("sweep", 600, 100, 80, 4, SlamSystem::Mode::Sequential);
  ASSERT_EQ(a.estimate.size(), b.estimate.size());
  ASSERT_GT(a.estimate.size(), 40u);
  for (size_t i = 0; i < a.estimate.size(); ++i)
    EXPECT_EQ(a.estimate.poses[i].matrix(), b.estimate.poses[i].matrix()) << i;
}

// The count of frames whose keyframe waited on mapping: none where tracking and mapping take
// turns (sequential) or tracking waits for mapping (offline); some in real time when frames
// come faster than mapping takes keyframes (here, as fast as tracking goes: about 10 ms a frame).
TEST(SlamSystem, RealTimeTrackingCountsTheKeyframesThatWaitedOnMapping) {
  // Each keyframe's mapping held 150 ms before its local BA, and no keyframe queued behind the
  // one being mapped. Slowed by settings alone (60 local BA iterations), mapping still kept up
  // on a fast, idle machine and none waited (fresh-clone CI runs): local BA converges in a few
  // iterations.
  struct SlowMapping : SystemEvents {
    void keyframeTriangulated(const std::shared_ptr<Map>&, const std::shared_ptr<KeyFrame>&) override {
      std::this_thread::sleep_for(std::chrono::milliseconds(150));
    }
  } slow;
  SlamSettings no_queue;
  no_queue.keyframe_queue = 0;
  auto run = [&](SlamSystem::Mode mode) { return runSequence("sweep", 600, 100, 80, 4, mode, nullptr, no_queue, &slow); };
  EXPECT_EQ(run(SlamSystem::Mode::Sequential).keyframes_deferred, 0);
  EXPECT_EQ(run(SlamSystem::Mode::Offline).keyframes_deferred, 0);
  const SlamRun realtime = run(SlamSystem::Mode::Realtime);
  EXPECT_GT(realtime.tracked, 60);
  EXPECT_GT(realtime.keyframes_deferred, 0);
}

// Through sweep's U-turn (up to 50 degrees a second) the keyframe chain carries the map's scale:
// with the turn rules at 5 degrees, tracking makes a keyframe every few degrees and culling keeps
// them, so no two keyframes next in time are more than the limit plus a frame's turn (2.5
// degrees) apart. Without them two were 13 degrees apart here.
TEST(SlamSystem, TurnRulesKeepTheKeyframeChainDenseThroughATurn) {
  SlamSettings plain_settings;
  plain_settings.keyframe_turn_deg = 0.0;
  plain_settings.keyframe_culling_max_angle_deg = 0.0;
  const SlamRun plain = runSequence("sweep", 800, 300, 130, 4, SlamSystem::Mode::Sequential, nullptr, plain_settings);
  SlamSettings dense;
  dense.keyframe_turn_deg = 5.0;
  dense.keyframe_culling_max_angle_deg = 5.0;
  const SlamRun turn = runSequence("sweep", 800, 300, 130, 4, SlamSystem::Mode::Sequential, nullptr, dense);
  EXPECT_GT(plain.widest_keyframe_step_deg, 8.0) << "the rules have nothing to do on this stretch";
  EXPECT_LE(turn.widest_keyframe_step_deg, 8.0);
  EXPECT_GT(turn.keyframes, plain.keyframes);
  EXPECT_GE(turn.tracked, 0.95 * turn.frames);
}

// The distribution layer sends a keyframe's new points before local BA (TR tracks with them a
// BA earlier): the event comes once per mapped keyframe, before keyframeMapped, with the
// keyframe already seeing points it did not see when tracking made it.
TEST(SlamSystem, NewPointsAreReportedBeforeLocalBa) {
  struct Recorder : SystemEvents {
    std::mutex mutex;
    std::map<Id, size_t> at_creation, at_triangulation;
    std::vector<Id> order;  // +id: triangulated, -id: mapped
    static size_t seen(const std::shared_ptr<Map>& map, const KeyFrame& kf) {
      std::lock_guard lock(map->mutex);
      size_t n = 0;
      for (const auto& p : kf.points) n += p && !p->bad;
      return n;
    }
    void keyframeTriangulated(const std::shared_ptr<Map>& map, const std::shared_ptr<KeyFrame>& kf) override {
      const size_t n = seen(map, *kf);
      std::lock_guard lock(mutex);
      at_triangulation[kf->id] = n;
      order.push_back(static_cast<Id>(kf->id));
    }
    void keyframeMapped(const std::shared_ptr<Map>&, const std::shared_ptr<KeyFrame>& kf) override {
      std::lock_guard lock(mutex);
      order.push_back(~static_cast<Id>(kf->id));
    }
  } recorder;
  const Sweep sweep;
  const auto& model = sweep.model;
  const auto& rays = sweep.rays;
  const auto& camera = sweep.camera;
  SlamSystem slam(SlamSettings{}, camera, SlamSystem::Mode::Offline);
  slam.setEvents(&recorder);
  for (int f = 100; f < 180; ++f) slam.process(model.renderImage(f, rays), model.stamp(f));
  slam.finish();
  std::lock_guard lock(recorder.mutex);
  ASSERT_GE(recorder.at_triangulation.size(), 5u);
  // Each keyframe: triangulated, then mapped, never the other way round.
  std::map<Id, int> state;
  for (Id e : recorder.order) {
    const bool mapped = static_cast<int64_t>(e) < 0;
    const Id id = mapped ? ~e : e;
    EXPECT_EQ(state[id], mapped ? 1 : 0) << id;
    state[id] = mapped ? 2 : 1;
  }
  // Triangulation added points: each keyframe sees more than tracking linked it to.
  size_t grew = 0;
  for (const auto& r : slam.frames())
    if (r.keyframe && r.reference && recorder.at_triangulation.count(r.reference->id))
      grew += recorder.at_triangulation[r.reference->id] > static_cast<size_t>(r.inliers);
  EXPECT_GE(grew, recorder.at_triangulation.size() / 2);
}


// New points must lie on the scene. A false match along an epipolar band still triangulates
// (two rays that meet the epipolar constraint meet somewhere), often centimetres from the
// cameras, and one such point outweighs a hundred true ones in the next frames' poses. Each
// keyframe's points are checked as local mapping makes them, against the true distance to the
// scene along their rays; the keyframe's own median ratio stands in for the map's scale. A
// point more than 25% off that counts as off the scene.
struct NewPointCheck : SystemEvents {
  NewPointCheck(const synth::SequenceModel& model, const std::map<double, int>& frame_at)
      : model(model), frame_at(frame_at) {}
  const synth::SequenceModel& model;
  const std::map<double, int>& frame_at;
  size_t created = 0, off = 0;

  void keyframeTriangulated(const std::shared_ptr<Map>& map, const std::shared_ptr<KeyFrame>& kf) override {
    std::lock_guard lock(map->mutex);
    const Eigen::Isometry3d T_wc = model.pose(frame_at.at(kf->frame.timestamp));
    std::vector<double> ratios;
    std::vector<bool> is_new;
    for (size_t i = 0; i < kf->points.size(); ++i) {
      const auto& p = kf->points[i];
      if (!p || p->bad) continue;
      const Eigen::Vector3d dir = (T_wc.linear() * kf->frame.K.ray(kf->frame.points[i])).normalized();
      const auto hit = model.scene.intersect(T_wc.translation(), dir);
      if (!hit) continue;
      ratios.push_back((p->position - kf->center()).norm() / hit->t);
      is_new.push_back(p->first_keyframe == kf->id);
    }
    if (ratios.size() < 20) return;
    std::vector<double> sorted = ratios;
    std::nth_element(sorted.begin(), sorted.begin() + static_cast<long>(sorted.size() / 2), sorted.end());
    const double scale = sorted[sorted.size() / 2];
    for (size_t k = 0; k < ratios.size(); ++k) {
      if (!is_new[k]) continue;
      ++created;
      off += std::abs(ratios[k] / scale - 1) > 0.25;
    }
  }
};

std::pair<size_t, size_t> newPointsOffTheScene(const SlamSettings& settings) {
  // Frames 200-360 of the standard figure8: its fast turn past a box.
  synth::SequenceOptions o;
  o.trajectory = "figure8";
  o.frames = 1000;
  o.seed = 2;
  const auto model = synth::buildSequence(o);
  const synth::RayTable rays(model.lens);
  auto camera = std::make_shared<camera::PinholeRadTan>(model.lens.width, model.lens.height, model.lens.fx,
                                                        model.lens.fy, model.lens.cx, model.lens.cy);
  std::map<double, int> frame_at;
  for (int f = 200; f < 360; ++f) frame_at[model.stamp(f)] = f;
  NewPointCheck check(model, frame_at);
  SlamSystem slam(settings, camera, SlamSystem::Mode::Sequential, shippedVocabulary());
  slam.setEvents(&check);
  for (int f = 200; f < 360; ++f) slam.process(model.renderImage(f, rays), model.stamp(f));
  slam.finish();
  return {check.created, check.off};
}

TEST(SlamSystem, NewPointsLieOnTheSceneThroughAFastTurn) {
  // Measured: 4.4-4.5% off with either search; about two thirds of those at under half their
  // true distance.
  for (const bool by_vocabulary : {false, true}) {
    SlamSettings settings;
    settings.triangulation_by_vocabulary = by_vocabulary;
    const auto [created, off] = newPointsOffTheScene(settings);
    ASSERT_GT(created, 2000u) << by_vocabulary;
    EXPECT_LT(static_cast<double>(off), 0.06 * static_cast<double>(created)) << by_vocabulary;
  }
}

}  // namespace
}  // namespace hiveslam::core
