// Occluder tracking speed: BM_OccluderTracker/<points>, one frame's update
// (clustering, association, registration, Kalman filter) of a hand-sized
// cluster of occluder supervoxels moving at 0.5 m/s, seen at 30 Hz.
#include "ofv/occluder_tracker.h"

#include <benchmark/benchmark.h>

#include <random>

namespace {

void BM_OccluderTracker(benchmark::State& state) {
  const auto n = static_cast<Eigen::Index>(state.range(0));
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  Eigen::Matrix3Xd hand(3, n);
  for (Eigen::Index k = 0; k < n; ++k) hand.col(k) = Eigen::Vector3d(0.10 * unit(rng), 0.05 * unit(rng), 0.015 * unit(rng));
  constexpr double dt = 1.0 / 30.0;
  const Eigen::Vector3d step(0.5 * dt, 0.0, 0.0);
  ofv::OccluderTracker tracker;
  Eigen::Matrix3Xd seen = hand;
  for (auto _ : state) {
    seen.colwise() += step;
    benchmark::DoNotOptimize(tracker.update(seen, dt));
  }
  state.counters["tracks"] = static_cast<double>(tracker.tracks().size());
  state.counters["speed"] = tracker.tracks().empty() ? 0.0 : tracker.tracks().front().velocity.norm();
}
BENCHMARK(BM_OccluderTracker)->Arg(100)->Arg(500)->Arg(1000)->Unit(benchmark::kMicrosecond);

}  // namespace
