// Estimator speed: BM_Estimate/<supervoxels>/<occluders>, BM_EstimateWarmArm/<supervoxels>/<occluders>,
// BM_EstimateWarmArmOnField/<supervoxels>/<occluders>.
#include "scenes.h"

#include <benchmark/benchmark.h>

namespace {

// Every call prepares its problem (ofv::OcclusionField) and iterates.
void estimate(benchmark::State& state, const ofv::ViewProblem& problem, const ofv::EstimatorSettings& settings) {
  int iterations = 0;
  for (auto _ : state) {
    const ofv::ViewEstimate e = ofv::estimate_view(problem, settings);
    iterations = e.iterations;
    benchmark::DoNotOptimize(e.tf);
  }
  state.counters["iterations"] = iterations;
}

void BM_Estimate(benchmark::State& state) {
  estimate(state,
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
  estimate(state,
                       ofv::bench::patch_behind_sweeping_arm(static_cast<int>(state.range(0)),
                                                             static_cast<int>(state.range(1))),
                       settings);
}
BENCHMARK(BM_EstimateWarmArm)->Args({90, 1300})->Unit(benchmark::kMicrosecond);

// The same warm start on a field prepared once (the loop's second and third
// estimates of a frame): the iteration alone.
void BM_EstimateWarmArmOnField(benchmark::State& state) {
  ofv::EstimatorSettings settings;
  settings.warm_start = true;
  const ofv::ViewProblem problem = ofv::bench::patch_behind_sweeping_arm(static_cast<int>(state.range(0)),
                                                                        static_cast<int>(state.range(1)));
  const ofv::OcclusionField field(problem, settings.r_sphere);
  int iterations = 0;
  for (auto _ : state) {
    const ofv::ViewEstimate e = ofv::estimate_view(field, settings, problem.previous_view);
    iterations = e.iterations;
    benchmark::DoNotOptimize(e.tf);
  }
  state.counters["iterations"] = iterations;
}
BENCHMARK(BM_EstimateWarmArmOnField)->Args({90, 1300})->Unit(benchmark::kMicrosecond);

}  // namespace
