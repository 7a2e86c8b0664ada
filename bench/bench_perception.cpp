// Perception front end speed: BM_Perception/<width> on a tracking frame
// (table, DVD case held by a hand, an arm in front), 640x480, 320x240 and
// 1280x720, with the default supervoxel stage (ofv's);
// BM_PerceptionPclSupervoxels/<width> with PCL's, the reference.
// Counters give each stage's mean wall time [ms] and the sizes it worked on.
// BM_PerceptionScores/<width>: scoring that frame's result against its labels.
#include "ofv/perception/perception.h"
#include "ofv/perception/scores.h"

#include "synthetic_scene.h"  // test/perception: analytic ray casting

#include <benchmark/benchmark.h>

#include <algorithm>
#include <cstdint>

namespace {

/// 320x240, 640x480 (4:3, 615 px focal length at 640) or 1280x720 (16:9, the same field across).
ofv::CameraIntrinsics intrinsics(int width) {
  ofv::CameraIntrinsics k = ofv::test::vga(width);
  if (width == 1280) {
    k.height = 720;
    k.cy = 360.0;
  }
  return k;
}

ofv::RgbdFrame scene_frame(int width, std::vector<int>* labels = nullptr) {
  using namespace ofv::test;
  SyntheticScene scene = table_and_case();
  const Eigen::Vector3d skin(225, 170, 140);
  scene.shapes.push_back(
      make_capsule({0.115, -0.005, 0.03}, {0.115, -0.005, 0.12}, 0.02, skin, kHand));
  scene.shapes.push_back(
      make_capsule({-0.15, -0.2, 0.08}, {0.05, -0.22, 0.16}, 0.025, skin, kHand));
  return scene.render(intrinsics(width), front_camera(), labels);
}

/// The front end on the frame with the supervoxel stage `method`.
void perception_on_frame(benchmark::State& state, ofv::perception::SupervoxelSettings::Method method) {
  const int width = static_cast<int>(state.range(0));
  const ofv::RgbdFrame frame = scene_frame(width);
  ofv::perception::PerceptionSettings settings;
  settings.supervoxels.method = method;
  ofv::perception::Perception perception{settings};
  (void)perception.process(frame);  // frame 0: selection
  ofv::perception::PerceptionTimings sum;
  ofv::perception::PerceptionCounts counts;
  for (auto _ : state) {
    const ofv::perception::PerceptionResult r = perception.process(frame);
    if (r.status == ofv::perception::TrackingStatus::Lost) {
      state.SkipWithError("object lost");
      break;
    }
    sum.cloud += r.timings.cloud;
    sum.supervoxels += r.timings.supervoxels;
    sum.adjacency += r.timings.adjacency;
    sum.tracking += r.timings.tracking;
    sum.classify += r.timings.classify;
    counts = r.counts;
    benchmark::DoNotOptimize(r.problem.positions.data());
  }
  const auto n = static_cast<double>(state.iterations());
  state.counters["cloud_ms"] = sum.cloud / n;
  state.counters["supervoxels_ms"] = sum.supervoxels / n;
  state.counters["adjacency_ms"] = sum.adjacency / n;
  state.counters["tracking_ms"] = sum.tracking / n;
  state.counters["classify_ms"] = sum.classify / n;
  state.counters["voxels"] = static_cast<double>(counts.voxels);
  state.counters["supervoxels"] = static_cast<double>(counts.supervoxels);
  state.counters["object"] = static_cast<double>(counts.object);
  state.counters["occluders"] = static_cast<double>(counts.occluders);
}

void BM_Perception(benchmark::State& state) {
  perception_on_frame(state, ofv::perception::SupervoxelSettings{}.method);
}
BENCHMARK(BM_Perception)->Arg(640)->Arg(320)->Arg(1280)->Unit(benchmark::kMillisecond)->UseRealTime();

// The same with PCL's supervoxel stage (supervoxels=pcl).
void BM_PerceptionPclSupervoxels(benchmark::State& state) {
  perception_on_frame(state, ofv::perception::SupervoxelSettings::Method::Pcl);
}
BENCHMARK(BM_PerceptionPclSupervoxels)->Arg(640)->Arg(320)->Arg(1280)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_PerceptionScores(benchmark::State& state) {
  std::vector<int> labels;
  ofv::RgbdFrame frame = scene_frame(static_cast<int>(state.range(0)), &labels);
  // The synthetic scene's labels as the simulator's: the case the object,
  // the table its support, the hands occluding bodies.
  frame.labels.resize(labels.size());
  std::transform(labels.begin(), labels.end(), frame.labels.begin(), [](int l) -> std::uint16_t {
    switch (l) {
      case ofv::test::kObject: return ofv::kPixelObject;
      case ofv::test::kTable: return ofv::kPixelSupport;
      case ofv::test::kNone: return ofv::kPixelNone;
      default: return static_cast<std::uint16_t>(ofv::kPixelOccluder0 + l);
    }
  });
  const ofv::perception::PerceptionSettings settings;
  ofv::perception::Perception perception{settings};
  (void)perception.process(frame);
  const ofv::perception::PerceptionResult r = perception.process(frame);
  ofv::perception::PerceptionTruth truth;
  truth.centroid = r.centroid;
  truth.r_sphere = settings.r_sphere;
  for (auto _ : state) {
    const ofv::perception::PerceptionScores s = ofv::perception::score_perception(frame, r, truth, settings);
    benchmark::DoNotOptimize(s.object_cells);
  }
}
BENCHMARK(BM_PerceptionScores)->Arg(640)->Arg(320)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
