// Estimator speed: BM_Estimate/<supervoxels>/<occluders>.
#include "scenes.h"

#include <benchmark/benchmark.h>

namespace {

void BM_Estimate(benchmark::State& state) {
  const ofv::ViewProblem problem = ofv::bench::flat_patch_with_occluders(
      static_cast<int>(state.range(0)), static_cast<int>(state.range(1)));
  const ofv::EstimatorSettings settings;
  int iterations = 0;
  for (auto _ : state) {
    const ofv::ViewEstimate e = ofv::estimate_view(problem, settings);
    iterations = e.iterations;
    benchmark::DoNotOptimize(e.tf);
  }
  state.counters["iterations"] = iterations;
}
BENCHMARK(BM_Estimate)
    ->Args({25, 0})
    ->Args({25, 50})
    ->Args({50, 80})
    ->Args({100, 100})
    ->Args({400, 400})
    ->Unit(benchmark::kMicrosecond);

}  // namespace
