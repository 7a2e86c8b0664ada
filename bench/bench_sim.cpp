// Rendering speed: one frame of the default scenario at 320x240 and 640x480,
// and the ground truth (visibility of the object surface samples).
#include "ofv/sim/renderer.h"

#include <benchmark/benchmark.h>

namespace {

void BM_Render(benchmark::State& state) {
  const ofv::sim::Scenario s = ofv::sim::load_scenario(ofv::sim::kDefaultScenario);
  ofv::sim::Renderer renderer(s);
  renderer.set_time(2.0);
  ofv::CameraIntrinsics k = ofv::sim::intrinsics_preset(state.range(0) == 640 ? "d435-640" : "fast-320");
  long frame = 0;
  ofv::sim::RenderedFrame r;  // as the episode loop renders: into the previous frame's memory
  for (auto _ : state) {
    renderer.render(s.wMc_start, frame++, k, true, r);
    benchmark::DoNotOptimize(r.frame.depth.data());
  }
}
BENCHMARK(BM_Render)->Arg(320)->Arg(640)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_RenderSetTime(benchmark::State& state) {  // rebuilding the moving geometry
  const ofv::sim::Scenario s = ofv::sim::load_scenario("cloth-occluder");
  ofv::sim::Renderer renderer(s);
  double t = 0.0;
  for (auto _ : state) renderer.set_time(t += 1.0 / 30.0);
}
BENCHMARK(BM_RenderSetTime)->Unit(benchmark::kMillisecond);

void BM_GroundTruth(benchmark::State& state) {
  const ofv::sim::Scenario s = ofv::sim::load_scenario(ofv::sim::kDefaultScenario);
  ofv::sim::Renderer renderer(s);
  renderer.set_time(2.0);
  for (auto _ : state) benchmark::DoNotOptimize(renderer.truth(s.wMc_start, 0.5).visible_fraction);
}
BENCHMARK(BM_GroundTruth)->Unit(benchmark::kMillisecond);

}  // namespace
