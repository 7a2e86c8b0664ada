// The servo layer alone: one controller update per law, and one robot step
// per robot model (the free-flying camera and the arms on ViSP's kinematics).
#include "ofv/servo/controller.h"
#include "ofv/servo/robot.h"

#include <benchmark/benchmark.h>

#include <array>

namespace {

// Camera 0.5 m from the object at the origin, target 40 degrees away on the sphere.
vpHomogeneousMatrix start_pose() {
  vpHomogeneousMatrix wMc;
  wMc[2][3] = -0.5;  // on -z, looking along +z at the origin
  return wMc;
}

// Arg 0: PBVS, 1: the sphere feature.
void BM_ControllerUpdate(benchmark::State& state) {
  ofv::servo::ControllerSettings settings;
  settings.law = state.range(0) == 0 ? ofv::servo::ControllerSettings::Law::Pbvs : ofv::servo::ControllerSettings::Law::Sphere;
  ofv::servo::ViewController controller(settings);
  const vpHomogeneousMatrix wMc = start_pose();
  const Eigen::Vector3d target(0.5 * std::sin(0.7), 0.0, -0.5 * std::cos(0.7));
  for (auto _ : state) {
    vpColVector v = controller.update(target, Eigen::Vector3d::Zero(), 0.5, wMc, 1.0 / 30.0);
    benchmark::DoNotOptimize(v.data);
  }
}
BENCHMARK(BM_ControllerUpdate)->Arg(0)->Arg(1)->Unit(benchmark::kMicrosecond);

// Arg: 0 camera, 1 viper850, 2 afma6.
void BM_RobotStep(benchmark::State& state) {
  static const std::array<ofv::servo::RobotKind, 3> kinds{ofv::servo::RobotKind::Camera, ofv::servo::RobotKind::Viper850, ofv::servo::RobotKind::Afma6};
  const auto robot = ofv::servo::make_robot(kinds[static_cast<std::size_t>(state.range(0))], start_pose());
  state.SetLabel(robot->name());
  vpColVector v(6, 0.0);
  v[0] = 0.01;
  v[4] = 0.02;
  double sign = 1.0;
  for (auto _ : state) {
    const ofv::servo::RobotStep r = robot->step(sign * v, 1.0 / 30.0);  // back and forth, away from the limits
    benchmark::DoNotOptimize(r.wMc.data);
    sign = -sign;
  }
}
BENCHMARK(BM_RobotStep)->DenseRange(0, 2)->Unit(benchmark::kMicrosecond);

}  // namespace
