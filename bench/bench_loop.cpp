// The whole simulated closed-loop step (render 320x240 or 640x480 + perception
// + estimate + control + robot step + the per-frame scores) on the default
// scenario: steps per second over its whole episode (4 s; the hand comes into
// view at 1.5 s and stays: a one-second episode measured only the quiet
// start), >= 30 keeps up with the sensor; the throughput of `ofv compare` in
// episodes per minute; and the hindsight planner's time.
#include "ofv/loop/compare.h"
#include "ofv/loop/episode.h"

#include <benchmark/benchmark.h>

#include <chrono>
#include <filesystem>
#include <unistd.h>

namespace {

// Args: perception (0 ground truth, 1 full with PCL's supervoxels, 2 full
// with ofv's), the sensor's width (320: the scenario's fast-320; 640: d435-640).
void BM_ClosedLoopStep(benchmark::State& state) {
  ofv::sim::Scenario s = ofv::sim::load_scenario(ofv::sim::kDefaultScenario);
  if (state.range(1) == 640) s.sensor.intrinsics = ofv::sim::intrinsics_preset("d435-640");
  const std::string perception = state.range(0) ? "full" : "ground-truth";
  const std::string supervoxels = state.range(0) == 2 ? "ofv" : "pcl";
  ofv::EpisodeSetup setup;
  try {
    setup = ofv::resolve_episode(s, {{"perception", perception}, {"supervoxels", supervoxels}});
  } catch (const std::exception& e) {
    state.SkipWithError(e.what());
    return;
  }
  long steps = 0;
  for (auto _ : state) {
    const ofv::EpisodeOutcome o = ofv::run_episode(setup);
    steps += static_cast<long>(o.steps.size());
  }
  state.SetItemsProcessed(steps);  // items_per_second: closed-loop steps per second
}
BENCHMARK(BM_ClosedLoopStep)
    ->ArgsProduct({{0, 1, 2}, {320, 640}})
    ->ArgNames({"perception", "width"})
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

// ofv compare's harness on 4 built-in scenarios x 2 seeds of 2-second
// episodes, the paper's settings. Args: jobs, perception (0 ground truth, 1
// full with PCL's supervoxels, 2 full with ofv's).
void BM_CompareThroughput(benchmark::State& state) {
  const int jobs = static_cast<int>(state.range(0));
  std::vector<std::pair<std::string, std::string>> scenarios;
  for (const char* name : {"dvd-one-hand", "dvd-two-hands", "cloth-occluder", "sweep"}) {
    const ofv::sim::Scenario s = ofv::sim::load_scenario(name);  // resolves built-in names to their file
    scenarios.emplace_back(s.name, s.path);
  }
  ofv::Grid grid;
  grid.seeds = 2;
  grid.variants = {{"paper",
                    {{"perception", state.range(1) ? "full" : "ground-truth"},
                     {"supervoxels", state.range(1) == 2 ? "ofv" : "pcl"},
                     {"duration", "2.0"}}}};
  const auto episodes = ofv::plan_episodes(scenarios, grid);
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("ofv_bench_compare_" + std::to_string(::getpid()));
  ofv::SweepOptions options;
  options.jobs = jobs;
  long done = 0;
  double seconds = 0.0;
  for (auto _ : state) {
    std::filesystem::remove_all(dir);  // a fresh sweep, nothing to resume
    const auto start = std::chrono::steady_clock::now();
    done += ofv::run_sweep(episodes, ofv::simulation_runner(), dir.string(), options);
    seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  }
  std::filesystem::remove_all(dir);
  state.counters["episodes_per_min"] = 60.0 * static_cast<double>(done) / seconds;
}
BENCHMARK(BM_CompareThroughput)
    ->ArgsProduct({{1, 2}, {0, 1, 2}})
    ->ArgNames({"jobs", "full"})
    ->Unit(benchmark::kSecond)
    ->UseRealTime()
    ->Iterations(1);

// The hindsight planner (method hindsight) on seed 0 of a scenario at its
// defaults, the episode that follows the plan included (a small part):
// `plan_s` the planning time, `evaluations` the visibility evaluations made
// (views x steps at most). Arg: 0 sweep (5 s at 30 Hz, an arm crossing), 1
// moving-object (5 s, the object sliding), 2 cloth-occluder (4 s, a waving
// cloth and a hand: the costliest of the built-in scenarios).
void BM_HindsightPlan(benchmark::State& state) {
  const char* names[] = {"sweep", "moving-object", "cloth-occluder"};
  ofv::EpisodeSetup setup;
  try {
    setup = ofv::resolve_episode(ofv::sim::load_scenario(names[state.range(0)]), {{"method", "hindsight"}, {"seed", "0"}});
  } catch (const std::exception& e) {
    state.SkipWithError(e.what());
    return;
  }
  double plan_s = 0.0;
  long evaluations = 0;
  for (auto _ : state) {
    const ofv::EpisodeOutcome o = ofv::run_episode(setup);
    plan_s += o.metrics.hindsight->plan_s;
    evaluations += o.metrics.hindsight->evaluations;
  }
  state.counters["plan_s"] = plan_s / static_cast<double>(state.iterations());
  state.counters["evaluations"] = static_cast<double>(evaluations) / static_cast<double>(state.iterations());
}
BENCHMARK(BM_HindsightPlan)->DenseRange(0, 2)->ArgName("scenario")->Unit(benchmark::kSecond)->UseRealTime()->Iterations(1);

}  // namespace
