// Estimator speed: BM_Estimate/<supervoxels>/<occluders>.
#include "scenes.h"

#include <benchmark/benchmark.h>

namespace {

// Every call computes its occlusion rays: the estimator keeps the last
// problem's rays per thread (for the loop's second estimate of a frame), so
// the benchmark alternates between the problem and the same problem with its
// occluders in reverse order, which is the same work but not the same input.
void BM_Estimate(benchmark::State& state) {
  const ofv::ViewProblem problem = ofv::bench::flat_patch_with_occluders(
      static_cast<int>(state.range(0)), static_cast<int>(state.range(1)));
  ofv::ViewProblem reversed = problem;
  reversed.occluders = problem.occluders.rowwise().reverse();
  const ofv::ViewProblem* problems[2] = {&problem, &reversed};
  const ofv::EstimatorSettings settings;
  int iterations = 0;
  int k = 0;
  for (auto _ : state) {
    const ofv::ViewEstimate e = ofv::estimate_view(*problems[k], settings);
    k ^= 1;
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
