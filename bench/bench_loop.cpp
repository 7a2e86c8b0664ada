// The whole simulated closed-loop step (render 320x240 + perception + estimate
// + control + robot step) on the default scenario: steps per second over
// one-second episodes (>= 30 keeps up with the sensor).
#include "ofv/loop/episode.h"

#include <benchmark/benchmark.h>

namespace {

// Arg 0: ground-truth perception, 1: full perception.
void BM_ClosedLoopStep(benchmark::State& state) {
  const ofv::sim::Scenario s = ofv::sim::load_scenario(ofv::sim::kDefaultScenario);
  const std::string perception = state.range(0) ? "full" : "ground-truth";
  ofv::EpisodeSetup setup;
  try {
    setup = ofv::resolve_episode(s, {{"perception", perception}, {"duration", "1.0"}});
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
BENCHMARK(BM_ClosedLoopStep)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
