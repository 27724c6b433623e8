// Speed of the synthetic renderer: one frame of each standard-suite sequence at 752x480 on one
// thread (the suite renders frames in parallel on every core), and the scene build.
#include <benchmark/benchmark.h>

#include "synth/suite.hpp"

namespace {

using hiveslam::synth::RayTable;
using hiveslam::synth::SequenceModel;

const hiveslam::synth::SuiteEntry& entry(int i) {
  static const auto entries = hiveslam::synth::suite("standard");
  return entries[static_cast<size_t>(i)];
}

void RenderFrame(benchmark::State& state) {
  const auto& e = entry(static_cast<int>(state.range(0)));
  const SequenceModel model = hiveslam::synth::buildSequence(e.options);
  const RayTable rays(model.lens);
  int frame = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(model.renderImage(frame, rays));
    frame = (frame + 97) % e.options.frames;
  }
  state.SetLabel(e.name);
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(RenderFrame)->DenseRange(0, 3)->Unit(benchmark::kMillisecond);

void BuildScene(benchmark::State& state) {
  for (auto _ : state) benchmark::DoNotOptimize(hiveslam::synth::buildSequence(entry(0).options));
}
BENCHMARK(BuildScene)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
