// The closed loop: render → perceive → choose a view → control → move.
#include "ofv/loop/episode.h"

#include "ofv/io/scene_json.h"
#include "ofv/servo/robot.h"
#include "ofv/servo/target_pose.h"
#include "ofv/sim/renderer.h"

#ifdef OFV_LOOP_HAVE_PERCEPTION
#include "ofv/perception/perception.h"
#endif

#include <chrono>
#include <cmath>
#include <memory>
#include <stdexcept>

namespace ofv {

namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

double positive_number(const std::string& name, const std::string& value) {
  std::size_t used = 0;
  double v = 0.0;
  try {
    v = std::stod(value, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used != value.size() || !std::isfinite(v) || v <= 0.0) {
    throw std::invalid_argument("setting '" + name + "' must be a positive number, got \"" + value + "\"");
  }
  return v;
}

bool boolean(const std::string& name, const std::string& value) {
  if (value != "true" && value != "false") {
    throw std::invalid_argument("setting '" + name + "' must be true or false, got \"" + value + "\"");
  }
  return value == "true";
}

}  // namespace

const std::vector<std::string>& episode_setting_names() {
  static const std::vector<std::string> names{
      "method", "sampling_candidates", "sampling_occluder_radius", "controller", "gain",
      "max_linear_speed", "max_angular_speed", "target_filter", "target_hysteresis", "robot", "real_time",
      "perception", "duration", "seed"};
  return names;
}

EpisodeSetup resolve_episode(const sim::Scenario& scenario,
                             const std::vector<std::pair<std::string, std::string>>& settings) {
  EpisodeSetup s;
  s.scenario = scenario;
  s.robot = scenario.robot;
  s.duration = scenario.duration;
  // The scenario's controller section, then the settings.
  std::vector<std::pair<std::string, std::string>> all;
  for (const auto& [k, v] : scenario.controller) all.emplace_back(k == "law" ? "controller" : k, v);
  all.insert(all.end(), settings.begin(), settings.end());

  EstimatorParams params = scenario.estimator;
  const auto& estimator_names = param_names();
  for (const auto& [name, value] : all) {
    if (std::find(estimator_names.begin(), estimator_names.end(), name) != estimator_names.end()) {
      // Lengths may refer to the scenario's radii (e.g. push_radius=r_seed).
      std::string v = value;
      if (v == "r_seed") v = std::to_string(params.r_seed.value_or(0.02));
      if (v == "r_sphere") v = std::to_string(params.r_sphere.value_or(0.5));
      set_param(params, name, v);
    } else if (name == "method") {
      s.method = parse_view_method(value);
    } else if (name == "sampling_candidates") {
      const double n = positive_number(name, value);
      if (n != std::floor(n) || n > 1e6) throw std::invalid_argument("setting 'sampling_candidates' must be an integer in [1, 1e6], got \"" + value + "\"");
      s.sampling.candidates = static_cast<int>(n);
    } else if (name == "sampling_occluder_radius") {
      s.sampling.occluder_radius = positive_number(name, value);
    } else if (name == "controller") {
      if (value == "pbvs") {
        s.controller.law = ControllerSettings::Law::Pbvs;
      } else if (value == "sphere") {
        s.controller.law = ControllerSettings::Law::Sphere;
      } else {
        throw std::invalid_argument("setting 'controller' must be pbvs or sphere, got \"" + value + "\"");
      }
    } else if (name == "gain") {
      s.controller.gain = positive_number(name, value);
    } else if (name == "max_linear_speed") {
      s.controller.max_linear_speed = positive_number(name, value);
    } else if (name == "max_angular_speed") {
      s.controller.max_angular_speed = positive_number(name, value);
    } else if (name == "target_filter") {
      s.controller.target_filter = value == "0" ? 0.0 : positive_number(name, value);
    } else if (name == "target_hysteresis") {
      s.target_hysteresis = boolean(name, value);
    } else if (name == "real_time") {
      s.real_time = boolean(name, value);
    } else if (name == "robot") {
      if (value != "camera" && value != "viper850" && value != "afma6") {
        throw std::invalid_argument("setting 'robot' must be camera, viper850 or afma6, got \"" + value + "\"");
      }
      s.robot = value;
    } else if (name == "perception") {
      if (value == "full") {
        s.perception = PerceptionMode::Full;
      } else if (value == "ground-truth") {
        s.perception = PerceptionMode::GroundTruth;
      } else {
        throw std::invalid_argument("setting 'perception' must be full or ground-truth, got \"" + value + "\"");
      }
    } else if (name == "duration") {
      s.duration = positive_number(name, value);
    } else if (name == "seed") {
      std::size_t used = 0;
      long seed = -1;
      try {
        seed = std::stol(value, &used);
      } catch (const std::exception&) {
        used = 0;
      }
      if (used != value.size() || seed < 0) throw std::invalid_argument("setting 'seed' must be a non-negative integer, got \"" + value + "\"");
      s.scenario = sim::with_seed(scenario, static_cast<unsigned>(seed));
    } else {
      std::string list;
      for (const auto& n : estimator_names) list += (list.empty() ? "" : ", ") + n;
      for (const auto& n : episode_setting_names()) list += ", " + n;
      throw std::invalid_argument("unknown setting '" + name + "' (expected one of: " + list + ")");
    }
  }
  s.estimator = params.resolve();
  validate(s.controller);
  if (s.real_time && s.robot == "camera") {
    throw std::invalid_argument("setting 'real_time' needs robot viper850 or afma6 (ViSP's threaded simulators)");
  }
  return s;
}

EpisodeOutcome run_episode(const EpisodeSetup& setup, const StepObserver& observer) {
  const sim::Scenario& scenario = setup.scenario;
  const double dt = 1.0 / scenario.rate;
  const auto steps = static_cast<long>(std::floor(setup.duration * scenario.rate + 1e-9)) + 1;
  const double r_sphere = setup.estimator.r_sphere;
  const double r_seed = setup.estimator.r_seed;

  sim::Renderer renderer(scenario);
  std::unique_ptr<CameraRobot> robot = make_robot(setup.robot, to_visp(scenario.wMc_start), setup.real_time);
  ViewController controller(setup.controller);
#ifdef OFV_LOOP_HAVE_PERCEPTION
  std::unique_ptr<Perception> perception;
  if (setup.perception == PerceptionMode::Full) {
    PerceptionSettings ps;
    ps.r_sphere = r_sphere;
    ps.supervoxels.seed_resolution = r_seed;
    perception = std::make_unique<Perception>(ps);
  }
#else
  if (setup.perception == PerceptionMode::Full) {
    throw std::runtime_error("full perception needs ofv built with the perception front end (OFV_BUILD_PERCEPTION=ON)");
  }
#endif

  EpisodeOutcome outcome;
  std::optional<Eigen::Vector3d> previous_view, previous_target;
  for (long k = 0; k < steps; ++k) {
    StepRecord rec;
    rec.time = static_cast<double>(k) * dt;
    const Eigen::Isometry3d wMc = to_eigen(robot->wMc());
    rec.wMc = wMc;

    auto start = Clock::now();
    renderer.set_time(rec.time);
    const sim::RenderedFrame rendered = renderer.render(wMc, k);
    rec.times.render = seconds_since(start);

    // Ground truth, for the metrics (and the input in ground-truth mode).
    const sim::ObjectTruth truth = renderer.truth(wMc, r_sphere);
    const ViewProblem gt_problem = renderer.ground_truth_problem(wMc, r_seed, r_sphere);
    rec.visible_fraction = truth.visible_fraction;
    rec.occluders_in_sphere = truth.occluders_in_sphere;
    rec.sphere_distance_error = (wMc.translation() - truth.centroid).norm() - r_sphere;
    rec.angular_error_deg =
        score_view(gt_problem, gt_problem.positions.cols() > 0 ? Eigen::Vector3d(gt_problem.positions.rowwise().mean()) : truth.centroid,
                   r_sphere, wMc.translation(), setup.sampling.occluder_radius)
            .mean_error_deg;

    start = Clock::now();
    std::optional<ViewProblem> problem;
    if (setup.perception == PerceptionMode::GroundTruth) {
      problem = gt_problem;
    }
#ifdef OFV_LOOP_HAVE_PERCEPTION
    else {
      PerceptionResult result = perception->process(rendered.frame);
      if (result.status != TrackingStatus::Lost) problem = std::move(result.problem);
    }
#endif
    rec.times.perception = seconds_since(start);

    start = Clock::now();
    std::optional<ViewEstimate> estimate;
    std::optional<Eigen::Vector3d> target;
    if (problem) {
      problem->camera = wMc.translation();
      problem->previous_view = previous_view;
      try {
        estimate = estimate_view(*problem, setup.estimator);
      } catch (const std::invalid_argument&) {
        estimate.reset();  // e.g. no usable supervoxel: treated as a lost object
      }
    }
    if (estimate) {
      rec.t0 = estimate->t0;
      rec.tf = estimate->tf;
      rec.iterations = estimate->iterations;
      rec.status = to_string(estimate->status);
      switch (setup.method) {
        case ViewMethod::Estimator: target = estimate->tf; break;
        case ViewMethod::InitialView: target = estimate->t0; break;
        case ViewMethod::Sampling:
          target = sample_best_view(*problem, estimate->centroid, r_sphere, setup.sampling).view;
          break;
        case ViewMethod::Static: break;
      }
      previous_view = estimate->tf;
      if (setup.target_hysteresis && previous_target && target) {
        if (setup.method == ViewMethod::Estimator && estimate->iterations > 0) {
          // t0 is occluded: continue from the previous target (the spec's warm
          // start), which stays where it is while clear and otherwise moves to
          // the nearest clear view. While t0 is clear, t0 is the target.
          ViewProblem from_previous = *problem;
          from_previous.previous_view = *previous_target;
          EstimatorSettings warm = setup.estimator;
          warm.warm_start = true;
          const ViewEstimate kept = estimate_view(from_previous, warm);
          if (kept.status != ViewStatus::NotConverged) target = kept.tf;
        } else if (setup.method == ViewMethod::Sampling) {
          // Keep the previous view while it sees as much as the new best.
          const Eigen::Vector3d previous = estimate->centroid + r_sphere * (*previous_target - estimate->centroid).normalized();
          const double r = setup.sampling.occluder_radius;
          if (score_view(*problem, estimate->centroid, r_sphere, previous, r).visible_fraction >=
              score_view(*problem, estimate->centroid, r_sphere, *target, r).visible_fraction) {
            target = previous;
          }
        }
      }
      previous_target = target;
      rec.target = target;
    } else {
      rec.status = "object_lost";
    }
    rec.times.estimate = seconds_since(start);

    start = Clock::now();
    vpColVector v(6, 0.0);
    if (target && setup.method != ViewMethod::Static) {
      v = controller.update(*target, estimate->centroid, r_sphere, robot->wMc(), dt);
    }
    rec.times.control = seconds_since(start);
    for (unsigned i = 0; i < 6; ++i) rec.velocity(i) = v[i];

    outcome.steps.push_back(rec);
    if (observer) {
      StepDetail detail;
      detail.frame = &rendered.frame;
      detail.problem = problem ? &*problem : nullptr;
      detail.estimate = estimate ? &*estimate : nullptr;
      detail.target = target.value_or(wMc.translation());
      detail.true_centroid = truth.centroid;
      observer(rec, detail);
    }
    if (k + 1 < steps) (void)robot->step(v, dt);
  }
  outcome.metrics = summarise(outcome.steps);
  return outcome;
}

EpisodeRunner simulation_runner() {
  return [](const EpisodeSpec& spec) {
    auto settings = spec.variant.settings;
    // Seed k of a scenario is the same world for every variant.
    settings.emplace_back("seed", std::to_string(spec.seed));
    return run_episode(resolve_episode(sim::load_scenario(spec.scenario_path), settings));
  };
}

}  // namespace ofv
