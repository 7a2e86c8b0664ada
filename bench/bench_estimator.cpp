// Estimator speed: BM_Estimate/<supervoxels>/<occluders>, BM_EstimateWarmArm/<supervoxels>/<occluders>.
#include "scenes.h"

#include <benchmark/benchmark.h>

namespace {

// Every call computes its occlusion rays: the estimator keeps the last
// problem's rays per thread (for the loop's second estimate of a frame), so
// the benchmark alternates between the problem and the same problem with its
// occluders in reverse order, which is the same work but not the same input.
void estimate_alternating(benchmark::State& state, const ofv::ViewProblem& problem,
                          const ofv::EstimatorSettings& settings) {
  ofv::ViewProblem reversed = problem;
  reversed.occluders = problem.occluders.rowwise().reverse();
  const ofv::ViewProblem* problems[2] = {&problem, &reversed};
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

void BM_Estimate(benchmark::State& state) {
  estimate_alternating(state,
                       ofv::bench::flat_patch_with_occluders(static_cast<int>(state.range(0)),
                                                             static_cast<int>(state.range(1))),
                       ofv::EstimatorSettings{});
}
BENCHMARK(BM_Estimate)
    ->Args({25, 0})
    ->Args({25, 50})
    ->Args({50, 80})
    ->Args({100, 100})
    ->Args({400, 400})
    ->Unit(benchmark::kMicrosecond);

// The loop's largest problems: many occlusion points (the arm and its
// predicted copies) and a warm start that must cross their rays.
void BM_EstimateWarmArm(benchmark::State& state) {
  ofv::EstimatorSettings settings;
  settings.warm_start = true;
  estimate_alternating(state,
                       ofv::bench::patch_behind_sweeping_arm(static_cast<int>(state.range(0)),
                                                             static_cast<int>(state.range(1))),
                       settings);
}
BENCHMARK(BM_EstimateWarmArm)->Args({90, 1300})->Unit(benchmark::kMicrosecond);

}  // namespace
