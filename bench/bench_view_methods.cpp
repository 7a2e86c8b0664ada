// The estimator against the sampling next-best-view planner on the same
// inputs: time per frame (the benchmark) and the visibility each achieves
// (counter `visible`: fraction of supervoxels seen past the occluders).
#include "ofv/view_methods.h"
#include "scenes.h"

#include <benchmark/benchmark.h>

namespace {

constexpr double kOccluderRadius = 0.015;

void BM_ViewEstimator(benchmark::State& state) {
  const ofv::ViewProblem p = ofv::bench::flat_patch_with_occluders(
      static_cast<int>(state.range(0)), static_cast<int>(state.range(1)));
  const ofv::EstimatorSettings s;
  ofv::ViewEstimate e;
  for (auto _ : state) {
    e = ofv::estimate_view(p, s);
    benchmark::DoNotOptimize(e.tf);
  }
  state.counters["visible"] = ofv::score_view(p, e.centroid, s.r_sphere, e.tf, kOccluderRadius).visible_fraction;
  state.counters["visible_t0"] = ofv::score_view(p, e.centroid, s.r_sphere, e.t0, kOccluderRadius).visible_fraction;
}
BENCHMARK(BM_ViewEstimator)->Args({25, 50})->Args({100, 100})->Unit(benchmark::kMicrosecond);

void BM_ViewSampling(benchmark::State& state) {
  const ofv::ViewProblem p = ofv::bench::flat_patch_with_occluders(
      static_cast<int>(state.range(0)), static_cast<int>(state.range(1)));
  const ofv::EstimatorSettings s;
  const ofv::ViewEstimate e = ofv::estimate_view(p, s);
  ofv::SamplingSettings sampling;
  sampling.candidates = static_cast<int>(state.range(2));
  sampling.occluder_radius = kOccluderRadius;
  ofv::ScoredView best;
  for (auto _ : state) {
    best = ofv::sample_best_view(p, e.centroid, s.r_sphere, sampling);
    benchmark::DoNotOptimize(best.view);
  }
  state.counters["visible"] = best.visible_fraction;
}
BENCHMARK(BM_ViewSampling)
    ->Args({25, 50, 500})
    ->Args({25, 50, 2000})
    ->Args({100, 100, 2000})
    ->Unit(benchmark::kMillisecond);

}  // namespace
