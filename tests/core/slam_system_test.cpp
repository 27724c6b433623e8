// The whole sequential pipeline on a short rendered sequence: tracks, stays accurate, and the
// same input gives the same trajectory.
#include <gtest/gtest.h>

#include "core/camera/pinhole_radtan.hpp"
#include "core/system/slam_system.hpp"
#include "eval/trajectory_error.hpp"
#include "synth/sequence.hpp"

namespace hiveslam::core {
namespace {

struct SlamRun {
  io::Trajectory estimate, truth;
  int frames = 0, tracked = 0;
};

// Frames [first, first + count) of a sequence of `total` frames (its speed set by `total`).
SlamRun runSequence(const std::string& trajectory, int total, int first, int count, uint64_t seed, SlamSystem::Mode mode) {
  synth::SequenceOptions o;
  o.trajectory = trajectory;
  o.frames = total;
  o.seed = seed;
  const auto model = synth::buildSequence(o);
  const synth::RayTable rays(model.lens);
  auto camera = std::make_shared<camera::PinholeRadTan>(model.lens.width, model.lens.height, model.lens.fx,
                                                        model.lens.fy, model.lens.cx, model.lens.cy);
  SlamSystem slam(SlamSettings{}, camera, mode);
  SlamRun run;
  for (int f = first; f < first + count; ++f) {
    slam.process(model.renderImage(f, rays), model.stamp(f));
    run.truth.add(model.stamp(f), model.pose(f));
  }
  slam.finish();
  const auto map = slam.largestMap();
  for (const auto& r : slam.frames()) {
    ++run.frames;
    if (!r.tracked) continue;
    ++run.tracked;
    if (r.map == map->id) run.estimate.add(r.timestamp, slam.poseOf(r));
  }
  return run;
}

TEST(SlamSystem, TracksARenderedLoopAccurately) {
  const SlamRun run = runSequence("loop", 400, 0, 250, 1, SlamSystem::Mode::Sequential);
  EXPECT_GE(run.tracked, 0.9 * run.frames);
  const auto ate = eval::computeAte(run.truth, run.estimate);
  EXPECT_LT(ate.stats.rmse, 0.01 * ate.reference_length) << ate.stats.rmse << " m over " << ate.reference_length;
}

// Threaded: tracking on this thread, local mapping on its own. Thread timing varies with the
// machine's load, so the bar is lower than the deterministic run's; TSan runs this test too.
TEST(SlamSystem, ThreadedModeTracks) {
  const SlamRun run = runSequence("loop", 400, 0, 250, 1, SlamSystem::Mode::Offline);
  EXPECT_GE(run.tracked, 0.8 * run.frames);
  const auto ate = eval::computeAte(run.truth, run.estimate);
  EXPECT_LT(ate.stats.rmse, 0.02 * ate.reference_length) << ate.stats.rmse << " m over " << ate.reference_length;
}

TEST(SlamSystem, SequentialModeIsDeterministic) {
  const SlamRun a = runSequence("sweep", 600, 100, 80, 4, SlamSystem::Mode::Sequential), b = runSequence("sweep", 600, 100, 80, 4, SlamSystem::Mode::Sequential);
  ASSERT_EQ(a.estimate.size(), b.estimate.size());
  ASSERT_GT(a.estimate.size(), 40u);
  for (size_t i = 0; i < a.estimate.size(); ++i)
    EXPECT_EQ(a.estimate.poses[i].matrix(), b.estimate.poses[i].matrix()) << i;
}

}  // namespace
}  // namespace hiveslam::core
