// Speed of the SLAM core's per-frame work at 752x480 with 1000 features: ORB extraction and
// the whole frame construction (extraction + undistortion + grid).
#include <benchmark/benchmark.h>

#include "core/camera/pinhole_radtan.hpp"
#include "core/frame/frame.hpp"
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

}  // namespace

BENCHMARK_MAIN();
