// Reading a scene file (`ofv estimate SCENE.json`): BM_SceneFromText/<supervoxels>.
// The time per supervoxel should not grow with their number.
#include "ofv/io/scene_json.h"
#include "scenes.h"

#include <benchmark/benchmark.h>
#include <nlohmann/json.hpp>

namespace {

void BM_SceneFromText(benchmark::State& state) {
  ofv::Scene scene;
  scene.problem = ofv::bench::flat_patch_with_occluders(static_cast<int>(state.range(0)), 10);
  const std::string text = ofv::scene_to_json(scene).dump();
  for (auto _ : state) benchmark::DoNotOptimize(ofv::scene_from_text(text, "bench.json").problem.positions.data());
  state.SetItemsProcessed(state.iterations() * state.range(0));
}
BENCHMARK(BM_SceneFromText)->Arg(10000)->Arg(100000)->Unit(benchmark::kMillisecond);

}  // namespace
