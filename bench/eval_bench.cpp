// Speed of trajectory evaluation: association and Umeyama alignment on long trajectories.
#include <benchmark/benchmark.h>

#include <cmath>

#include "eval/trajectory_error.hpp"

namespace {

hiveslam::io::Trajectory circle(int n, double stamp_offset) {
  hiveslam::io::Trajectory t;
  for (int i = 0; i < n; ++i) {
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.translation() = Eigen::Vector3d(std::cos(0.01 * i), std::sin(0.013 * i), 0.001 * i);
    t.add(0.05 * i + stamp_offset, T);
  }
  return t;
}

void Ate(benchmark::State& state) {
  const auto n = static_cast<int>(state.range(0));
  const auto ref = circle(n, 0.0), est = circle(n, 0.004);
  for (auto _ : state) benchmark::DoNotOptimize(hiveslam::eval::computeAte(ref, est));
  state.SetItemsProcessed(state.iterations() * n);
}
BENCHMARK(Ate)->Arg(1000)->Arg(10000)->Arg(100000)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
