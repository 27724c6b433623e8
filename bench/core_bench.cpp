// Speed of the SLAM core's per-frame work at 752x480 with 1000 features: ORB extraction,
// the whole frame construction (extraction + undistortion + grid) and pose-only optimization
// (called twice per tracked frame). End-to-end tracking time is `hiveslam run --realtime`'s
// tracking_ms (docs/BENCHMARKS.md).
#include <benchmark/benchmark.h>

#include "core/camera/pinhole_radtan.hpp"
#include <random>

#include "core/frame/frame.hpp"
#include "core/optim/pose_optimizer.hpp"
#include "synth/sequence.hpp"

namespace {

const cv::Mat& image() {
  static const cv::Mat img = [] {
    hiveslam::synth::SequenceOptions o;
    const auto model = hiveslam::synth::buildSequence(o);
    return model.renderImage(200, hiveslam::synth::RayTable(model.lens));
  }();
  return img;
}

void OrbExtract(benchmark::State& state) {
  hiveslam::features::OrbOptions o;
  o.features = static_cast<int>(state.range(0));
  const hiveslam::features::OrbExtractor orb(o);
  std::vector<cv::KeyPoint> kps;
  cv::Mat desc;
  for (auto _ : state) orb.extract(image(), kps, desc);
  state.counters["keypoints"] = static_cast<double>(kps.size());
}
BENCHMARK(OrbExtract)->Arg(1000)->Arg(2000)->Unit(benchmark::kMillisecond);

void MakeFrame(benchmark::State& state) {
  const hiveslam::features::OrbExtractor orb;
  const hiveslam::camera::PinholeRadTan cam(752, 480, 458.654, 457.296, 367.215, 248.375,
                                            {-0.28340811, 0.07395907, 0.00019359, 1.76187114e-05});
  for (auto _ : state) benchmark::DoNotOptimize(hiveslam::core::makeFrame(image(), 0, 0.0, orb, cam));
}
BENCHMARK(MakeFrame)->Unit(benchmark::kMillisecond);

// N observations of points 1-5 m ahead, 0.7 px noise, 10% gross outliers, a start pose 5 cm
// and 3 degrees off: what tracking hands the optimizer after projection matching.
void PoseOptimize(benchmark::State& state) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1, 1);
  std::normal_distribution<double> n(0, 0.7);
  const hiveslam::core::Intrinsics K{450, 450, 376, 240};
  std::vector<hiveslam::core::PoseObservation> obs;
  for (int i = 0; i < state.range(0); ++i) {
    const Eigen::Vector3d pc(2 * u(rng), 1.5 * u(rng), 3 + 2 * u(rng));
    hiveslam::core::PoseObservation o{pc, K.project(pc) + Eigen::Vector2d(n(rng), n(rng)), 1.0};
    if (i % 10 == 0) o.uv += Eigen::Vector2d(30 * u(rng), 30 * u(rng));
    obs.push_back(o);
  }
  Eigen::Isometry3d start = Eigen::Isometry3d::Identity();
  start.translation() = Eigen::Vector3d(0.05, -0.02, 0.03);
  start.linear() = Eigen::AngleAxisd(0.05, Eigen::Vector3d::UnitY()).toRotationMatrix();
  std::vector<bool> outlier;
  for (auto _ : state) {
    Eigen::Isometry3d T = start;
    benchmark::DoNotOptimize(hiveslam::core::optimizePose(K, obs, T, outlier));
  }
}
BENCHMARK(PoseOptimize)->Arg(300)->Arg(1000)->Unit(benchmark::kMicrosecond);

}  // namespace

BENCHMARK_MAIN();
