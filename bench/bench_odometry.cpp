// RGB-D odometry speed: BM_Odometry/<width>/<max_width> runs ofv::odometry::Odometry
// (ICP against a keyframe, the defaults but OdometrySettings::max_width) on frames of dvd-one-hand that the
// simulator renders with its noise at 320x240 or 640x480, the camera moving
// 2 mm and 0.1 degree a frame. The counters median_ms and p90_ms are the median and 90th percentile of the
// steps' own times (OdometryDiagnostics::ms); statuses other than ok count in `not_ok`.
#include "ofv/odometry/odometry.h"
#include "ofv/sim/renderer.h"
#include "ofv/sim/scenario.h"

#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>
#include <vector>

namespace {

void BM_Odometry(benchmark::State& state) {
  const int width = static_cast<int>(state.range(0));
  const ofv::sim::Scenario scenario = ofv::sim::load_scenario("dvd-one-hand");
  ofv::sim::Renderer renderer(scenario);
  renderer.set_time(0.0);
  ofv::CameraIntrinsics k;  // 640x480, f 615 px, scaled to the width
  const double scale = width / 640.0;
  k.width = width;
  k.height = width * 3 / 4;
  k.fx *= scale;
  k.fy *= scale;
  k.cx *= scale;
  k.cy *= scale;
  constexpr int kFrames = 60;
  std::vector<ofv::RgbdFrame> frames;
  for (int i = 0; i < kFrames; ++i) {
    // Out and back again, so that the sequence repeats without a jump.
    const double s = i < kFrames / 2 ? i : kFrames - i;
    const Eigen::Isometry3d cMc2(Eigen::Translation3d(0.002 * s, 0.0, 0.0) *
                                 Eigen::AngleAxisd(0.1 * s * M_PI / 180.0, Eigen::Vector3d::UnitY()));
    frames.push_back(renderer.render(scenario.wMc_start * cMc2, i, k, true).frame);
  }
  ofv::odometry::OdometrySettings settings;
  settings.max_width = static_cast<int>(state.range(1));
  ofv::odometry::Odometry odometry(settings);
  std::vector<double> ms;
  long not_ok = 0;
  std::size_t i = 0;
  (void)odometry.step(frames[0]);
  for (auto _ : state) {
    const ofv::odometry::OdometryResult r = odometry.step(frames[++i % frames.size()]);
    ms.push_back(r.diagnostics.ms);
    not_ok += r.status == ofv::odometry::OdometryStatus::Ok ? 0 : 1;
    benchmark::DoNotOptimize(r);
  }
  std::sort(ms.begin(), ms.end());
  state.counters["median_ms"] = ms.empty() ? 0.0 : ms[ms.size() / 2];
  state.counters["p90_ms"] = ms.empty() ? 0.0 : ms[ms.size() * 9 / 10];
  state.counters["not_ok"] = static_cast<double>(not_ok);
}
// 640x480 matched at 320x240 (the default) and at its own size.
BENCHMARK(BM_Odometry)->Args({320, 320})->Args({640, 320})->Args({640, 0})->Unit(benchmark::kMillisecond);

}  // namespace
