// Three nodes (TR, LM, LC) in one process on the in-process network: the rendered loop is
// tracked at TR with mapping and loop closing offloaded, the loop is closed at LC, and after the
// end-of-run exchange every node's S_full (and SLAM map) holds the same keyframes and points
// with poses equal to within 1 mm.
#include <gtest/gtest.h>

#include "communication/inproc/inproc_network.hpp"
#include "core/camera/pinhole_radtan.hpp"
#include "core/system/slam_system.hpp"
#include "distribution/distributed_node.hpp"
#include "eval/trajectory_error.hpp"
#include "synth/sequence.hpp"

namespace hiveslam::distribution {
namespace {

using communication::Task;

std::shared_ptr<const place::Vocabulary> shippedVocabulary() {
  static const auto voc = std::make_shared<const place::Vocabulary>(
      place::Vocabulary::load(std::string(HIVESLAM_SOURCE_DIR) + "/data/vocabulary/orb_k10_l4.bin"));
  return voc;
}

void expectSameState(const StateDigest& a, const StateDigest& b, const char* what) {
  EXPECT_EQ(a.keyframes.size(), b.keyframes.size()) << what;
  EXPECT_EQ(a.points.size(), b.points.size()) << what;
  int missing = 0;
  std::string missing_what;  // the first few, for the failure message
  const auto miss = [&](const char* kind, core::Id id) {
    if (++missing <= 4)
      missing_what += std::string(" ") + kind + " " + std::to_string(id) + " (node " +
                      std::to_string(core::IdGenerator::node(id)) + ")";
  };
  double worst = 0;
  std::string worst_what;  // which object, for the failure message
  for (const auto& [id, T] : a.keyframes) {
    auto it = b.keyframes.find(id);
    if (it == b.keyframes.end()) {
      miss("missing keyframe", id);
      continue;
    }
    const double d = (T.inverse().translation() - it->second.inverse().translation()).norm();
    if (d > worst) {
      worst = d;
      worst_what = "keyframe " + std::to_string(id);
    }
  }
  for (const auto& [id, p] : a.points) {
    auto it = b.points.find(id);
    if (it == b.points.end()) {
      miss("missing point", id);
      continue;
    }
    const double d = (p - it->second).norm();
    if (d > worst) {
      worst = d;
      worst_what = "point " + std::to_string(id) + " (node " + std::to_string(core::IdGenerator::node(id)) + ")";
    }
  }
  // And the other way round: what only the second holds.
  for (const auto& [id, T] : b.keyframes)
    if (!a.keyframes.count(id)) miss("extra keyframe", id);
  for (const auto& [id, p] : b.points)
    if (!a.points.count(id)) miss("extra point", id);
  EXPECT_EQ(missing, 0) << what << ":" << missing_what;
  EXPECT_LT(worst, 1e-3) << what << ": " << worst_what;
}

StateDigest slamState(const core::SlamSystem& slam) {
  StateDigest d;
  for (const auto& map : slam.liveMaps()) {
    std::lock_guard lock(map->mutex);
    for (const auto& [id, k] : map->keyframes) d.keyframes[id] = k->T_cw;
    for (const auto& [id, p] : map->points) d.points[id] = p->position;
  }
  return d;
}

// Runs a rendered sequence through TR, LM and LC on the in-process network to the end of the
// run, checks TR's accuracy, then that every node's S_full and SLAM maps agree.
struct ClusterRun {
  int tracked = 0, frames = 0;
  int mapped_by_tr = 0, mapped_by_new_lm = 0;  // keyframes local mapping processed there
  double ate_fraction = 1.0;  // ATE RMSE over the path length
  int loops = 0, merges = 0;
  size_t remeasured_tr = 0, remeasured_lc = 0;  // observations TR measured again; those LC held for its final BA
  core::RemeasurementUse remeasured_use;         // how LC's final BA used them
  size_t maps_tr = 0, maps_lm = 0, maps_lc = 0;
  int lc_maps_asked_for = 0;
};

// Frames at which the mapping node leaves, and at which it comes back: a new incarnation under
// the same id, with empty maps, as a restarted device would be.
struct Outage {
  int leaves = -1, returns = -1;
};

// `lost_to_lc`: the first packets LM sends LC keyframes in never arrive.
ClusterRun runThreeNodes(const std::string& trajectory, int frames, Outage outage = {}, int lost_to_lc = 0) {
  synth::SequenceOptions o;
  o.trajectory = trajectory;
  o.frames = frames;
  o.seed = 1;
  const auto model = synth::buildSequence(o);
  const synth::RayTable rays(model.lens);
  auto camera = std::make_shared<camera::PinholeRadTan>(model.lens.width, model.lens.height, model.lens.fx,
                                                              model.lens.fy, model.lens.cx, model.lens.cy);
  const auto voc = shippedVocabulary();
  using Mode = core::SlamSystem::Mode;
  core::SlamSystem tr(core::SlamSettings{}, camera, Mode::Offline, voc, 1);
  core::SlamSystem lm(core::SlamSettings{}, camera, Mode::Offline, voc, 2);
  core::SlamSystem lc(core::SlamSettings{}, camera, Mode::Offline, voc, 3);
  core::SlamSystem lm2(core::SlamSettings{}, camera, Mode::Offline, voc, 2);
  communication::InProcNetwork network;
  network.loseNext(communication::Topic::LmKeyframes, lost_to_lc);
  auto e_tr = network.endpoint(), e_lm = network.endpoint(), e_lc = network.endpoint(), e_lm2 = network.endpoint();
  DistributedNode n_lm(lm, *e_lm, {Task::Mapping, 2, "lm", {}});
  DistributedNode n_lm2(lm2, *e_lm2, {Task::Mapping, 2, "lm", {}});
  DistributedNode n_lc(lc, *e_lc, {Task::LoopClosing, 3, "lc", {}});
  DistributedNode n_tr(tr, *e_tr, {Task::Tracking, 1, "tr", {}});
  n_lm.start();
  n_lc.start();
  n_tr.start();
  EXPECT_FALSE(n_tr.plan().mapping);
  EXPECT_FALSE(n_tr.plan().loop_closing);
  EXPECT_FALSE(n_lm.plan().loop_closing);

  ClusterRun run;
  run.frames = o.frames;
  io::Trajectory truth;
  for (int f = 0; f < o.frames; ++f) {
    if (f == outage.leaves) n_lm.stop();
    if (f == outage.returns) n_lm2.start();
    tr.process(model.renderImage(f, rays), model.stamp(f));
    truth.add(model.stamp(f), model.pose(f));
  }
  const bool returned = outage.returns >= 0;
  DistributedNode& n_mapper = returned ? n_lm2 : n_lm;
  core::SlamSystem& mapper = returned ? lm2 : lm;
  EXPECT_TRUE(n_tr.finishRun(std::chrono::seconds(120)));
  EXPECT_TRUE(n_mapper.waitUntilDone(std::chrono::seconds(30)));
  EXPECT_TRUE(n_lc.waitUntilDone(std::chrono::seconds(30)));

  io::Trajectory estimate;
  const auto map = tr.largestMap();
  for (const auto& r : tr.frames()) {
    if (!r.tracked) continue;
    ++run.tracked;
    if (tr.currentMapId(r.map) == map->id) estimate.add(r.timestamp, tr.poseOf(r));
  }
  const auto ate = eval::computeAte(truth, estimate);
  run.ate_fraction = ate.stats.rmse / ate.reference_length;
  run.loops = lc.loopStats().loops;
  run.merges = lc.loopStats().merges;
  run.maps_tr = tr.liveMaps().size();
  run.maps_lm = mapper.liveMaps().size();
  run.maps_lc = lc.liveMaps().size();
  run.remeasured_tr = tr.remeasureReport().own;
  run.remeasured_lc = lc.remeasureReport().total;
  run.remeasured_use = lc.loopStats().remeasured;
  run.mapped_by_tr = tr.mappingStats().keyframes_processed;
  run.mapped_by_new_lm = lm2.mappingStats().keyframes_processed;
  run.lc_maps_asked_for = n_lc.report(1.0).value("maps_asked_for", 0);

  expectSameState(n_mapper.observer().digest(), n_tr.observer().digest(), "S_full LM vs TR");
  expectSameState(n_mapper.observer().digest(), n_lc.observer().digest(), "S_full LM vs LC");
  expectSameState(slamState(mapper), slamState(tr), "S_slam LM vs TR");
  expectSameState(slamState(mapper), slamState(lc), "S_slam LM vs LC");
  n_tr.stop();
  n_lm.stop();
  n_lm2.stop();
  n_lc.stop();
  tr.finish();
  lm.finish();
  lm2.finish();
  lc.finish();
  return run;
}

TEST(InProcCluster, ThreeNodesTrackCloseTheLoopAndAgree) {
  const ClusterRun run = runThreeNodes("loop", 500);
  EXPECT_GT(run.tracked, run.frames * 9 / 10);
  EXPECT_LT(run.ate_fraction, 0.01);
  EXPECT_GE(run.loops, 1);
  EXPECT_EQ(run.mapped_by_tr, 0);  // TR mapped nothing itself
  // TR alone holds the images: it measured the observations again, and LC's final BA got them all.
  EXPECT_GT(run.remeasured_tr, 1000u);
  EXPECT_EQ(run.remeasured_lc, run.remeasured_tr);
  // Nearly all for the point and anchor TR measured them for (the rest: points culled or fused
  // after TR's pass; a 3-node sweep run: 97.7% applied, 20 of 27,838 for another point or anchor).
  const auto& use = run.remeasured_use;
  EXPECT_GT(use.applied, run.remeasured_tr * 9 / 10);
  EXPECT_LT(use.other_point + use.other_anchor, run.remeasured_tr / 20);
}

// The mapping node leaves a third of the way round; TR maps alone (LC stays). It comes back at
// two thirds, restarted under its old id: TR hands it the map so far and mapping back. It must
// take over the whole map, not start a second copy from the keyframes that come after it
// joined (it once ended holding only what it mapped itself), and the points it makes must not
// reuse the ids of those its first incarnation made (they once did, and overwrote them). The
// loop is still closed with every node holding the same map at the end.
TEST(InProcCluster, AMappingNodeThatJoinsMidRunTakesTheWholeMapOver) {
  const ClusterRun run = runThreeNodes("loop", 500, {160, 330});
  EXPECT_GT(run.tracked, run.frames * 9 / 10);
  EXPECT_LT(run.ate_fraction, 0.01);
  EXPECT_GT(run.mapped_by_tr, 0);      // during the outage
  EXPECT_GT(run.mapped_by_new_lm, 0);  // after it joined
  EXPECT_GE(run.loops, 1);
  EXPECT_EQ(run.maps_lm, 1u);
}

// The packet that brings LC the map (its first keyframe, with the map's first as companion) is
// lost, as one written before LC's reader matched is over DDS. LC's next keyframes name a map
// it never got: it asks the gateway, which answers with a snapshot, and LC closes the loop in
// that map and ends the run holding what the others hold (CI: a loop-closing node
// that waited for a snapshot nobody sent ended with two keyframes known only by their records).
TEST(InProcCluster, ALoopClosingNodeThatMissedAMapsStartAsksForTheMap) {
  const ClusterRun run = runThreeNodes("loop", 500, {}, 1);
  EXPECT_EQ(run.lc_maps_asked_for, 1);
  EXPECT_GE(run.loops, 1);
  EXPECT_EQ(run.maps_lc, 1u);
  EXPECT_LT(run.ate_fraction, 0.01);
}

// After the blank stretch TR starts a second map; LC merges it into the first when TR sees
// the first map's places again. The merge must reach every node even when the global BA that
// follows it supersedes the merge's update before all its batches went out (a bench run found
// TR and LM still holding two maps, and LC's map short of the first map's keyframes).
TEST(InProcCluster, AMergeAfterABlackoutReachesEveryNode) {
  const ClusterRun run = runThreeNodes("blackout", 600);
  EXPECT_GE(run.merges, 1);
  EXPECT_EQ(run.maps_lc, 1u);
  EXPECT_EQ(run.maps_lm, 1u);
  EXPECT_EQ(run.maps_tr, 1u);
  EXPECT_LT(run.ate_fraction, 0.01);
}

}  // namespace
}  // namespace hiveslam::distribution
