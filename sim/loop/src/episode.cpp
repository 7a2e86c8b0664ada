// The closed loop in simulation: render → perceive → ViewLoop → move.
#include "ofv/loop/episode.h"

#include "ofv/servo/target_pose.h"
#include "ofv/sim/live_source.h"
#include "ofv/sim/renderer.h"
#ifdef OFV_LOOP_HAVE_ODOMETRY
#include "ofv/odometry/odometry.h"
#endif

#include <algorithm>
#include <chrono>
#include <cmath>
#include <deque>
#include <memory>
#include <stdexcept>

namespace ofv {

namespace {

using Clock = std::chrono::steady_clock;

double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

#ifndef OFV_LOOP_HAVE_ODOMETRY
// What OpenCV's contrib module the odometry needs, for the errors of a build without it.
constexpr const char* kNoOdometry =
    "needs RGB-D odometry, which this ofv was built without: it needs OpenCV's rgbd module (opencv_contrib; "
    "Debian's libopencv-contrib-dev)";
#endif

// Setting `poses`: simulator | robot | odometry[:METHOD].
void set_poses(EpisodeSetup& e, const std::string& word) {
  if (word == "simulator" || word == "robot") {
    e.poses = PoseOrigin::Frame;
    e.odometry_method.clear();
    return;
  }
  const std::string prefix = "odometry";
  const bool odometry = word.rfind(prefix, 0) == 0 &&
                        (word.size() == prefix.size() || (word[prefix.size()] == ':' && word.size() > prefix.size() + 1));
  if (!odometry) {
    throw std::invalid_argument("setting 'poses' must be one of " + std::string(kPosesWords) + ", got \"" + word + "\"");
  }
#ifdef OFV_LOOP_HAVE_ODOMETRY
  const std::string method = word.size() > prefix.size() ? word.substr(prefix.size() + 1) : std::string();
  if (!method.empty()) {
    try {
      (void)odometry::parse_method("poses", method);
    } catch (const std::invalid_argument&) {
      throw std::invalid_argument("setting 'poses' must be one of " + std::string(kPosesWords) + ", got \"" + word +
                                  "\"");
    }
  }
  e.poses = PoseOrigin::Odometry;
  e.odometry_method = method;
#else
  throw std::invalid_argument("setting poses = " + word + " " + kNoOdometry);
#endif
}

SettingsTable<EpisodeSetup> make_table() {
  using E = EpisodeSetup;
  const EpisodeSetup d;
  SettingsTable<E> t;
  t.include(servo::loop_settings_table(), [](auto& e) -> auto& { return e.loop; });
  t.include(perception::perception_settings_table(), [](auto& e) -> auto& { return e.front_end; });
  t.add({"robot", "camera | viper850 | afma6", "the scenario's", "",
         "free-flying camera, or the arm on ViSP's kinematic model (threaded simulator with real_time)"},
        [](E& e, const std::string& v) { e.robot = servo::parse_robot_kind(v); },
        [](const E& e) { return std::string(to_string(e.robot)); });
  t.add({"perception", "full | labels | ground-truth", to_string(d.perception), "",
         "the front end on the frames; the same with the rendered labels in place of segmentation and classification "
         "(the limit of any front end from this sensor); or the simulator's ground-truth supervoxels and every occluder "
         "in the sphere"},
        [](E& e, const std::string& v) {
          e.perception = parse_word<PerceptionMode>(
              "perception", v,
              {{"full", PerceptionMode::Full}, {"labels", PerceptionMode::Labels}, {"ground-truth", PerceptionMode::GroundTruth}});
        },
        [](const E& e) { return std::string(to_string(e.perception)); });
  t.add({"select", "labels | auto", to_string(d.select), "",
         "perception=full, simulation: how the first frame's object is found: the scenario's object from the "
         "labels (as a user points it out), or the front end's cluster at the image centre (ofv run's default)"},
        [](E& e, const std::string& v) {
          e.select = parse_word<ObjectSelect>("select", v, {{"labels", ObjectSelect::Labels}, {"auto", ObjectSelect::Auto}});
        },
        [](const E& e) { return std::string(to_string(e.select)); });
  t.add({"duration", "number in (0, 86400]", "the scenario's", "s", "length of the episode (ofv run: stop after this much source time)"},
        [](E& e, const std::string& v) { e.duration = parse_number("duration", v, 0.0, kMaxEpisodeDuration, true); },
        [](const E& e) { return format_number(e.duration); });
  t.add({"seed", "integer in [0, 1000000000]", std::to_string(d.seed), "",
         "the scenario's k-th random world: sensor noise and, for k > 0, occluder timing and placement"},
        [](E& e, const std::string& v) { e.seed = static_cast<unsigned>(parse_integer("seed", v, 0, 1000000000)); },
        [](const E& e) { return std::to_string(e.seed); });
  t.add({"latency", "integer in [0, 30]", std::to_string(d.latency), "frames",
         "delay between capturing a frame and applying its command (simulation), 0 to 30; (1 + latency) / rate must "
         "stay within stale_timeout"},
        [](E& e, const std::string& v) { e.latency = static_cast<int>(parse_integer("latency", v, 0, 30)); },
        [](const E& e) { return std::to_string(e.latency); });
  t.add({"hindsight_spacing", "number in [0.002, 0.2]", format_number(d.hindsight.spacing), "m",
         "method hindsight: spacing of the views on the sphere (each stands for spacing^2 of its area)"},
        [](E& e, const std::string& v) { e.hindsight.spacing = parse_number("hindsight_spacing", v, 0.002, 0.2, false); },
        [](const E& e) { return format_number(e.hindsight.spacing); });
  t.add({"hindsight_step", "integer in [1, 30]", std::to_string(d.hindsight.frames_per_step), "frames",
         "method hindsight: the planner's time step, in frame periods"},
        [](E& e, const std::string& v) { e.hindsight.frames_per_step = static_cast<int>(parse_integer("hindsight_step", v, 1, 30)); },
        [](const E& e) { return std::to_string(e.hindsight.frames_per_step); });
  t.add({"hindsight_segment", "integer in [1, 8]", std::to_string(d.hindsight.segment_steps), "steps",
         "method hindsight: the longest straight move at full speed between two views, in steps (1: one step at a "
         "time, which a lattice slows to about 0.6 of the speed limit)"},
        [](E& e, const std::string& v) { e.hindsight.segment_steps = static_cast<int>(parse_integer("hindsight_segment", v, 1, 8)); },
        [](const E& e) { return std::to_string(e.hindsight.segment_steps); });
  t.add({"poses", "simulator | robot | odometry[:icp|rgbd_icp|fast_icp|rgbd]", poses_word(d), "",
         "the camera pose the front end and the loop get: the frame's own (simulator: the true pose; ofv run: the "
         "robot's or the recording's; robot says the same), or RGB-D odometry from the first frame's pose (OpenCV's "
         "rgbd module; the renderer and the metrics keep the true pose); a frame whose pose odometry cannot tell "
         "stops the robot"},
        [](E& e, const std::string& v) { set_poses(e, v); }, [](const E& e) { return poses_word(e); });
#ifdef OFV_LOOP_HAVE_ODOMETRY
  // The odometry's own settings, prefixed (mask, min_depth ... would clash);
  // its method is setting poses'.
  for (const auto& row : odometry::odometry_settings_table().rows()) {
    if (row.doc.name == "odometry") continue;
    const std::string name = "odometry_" + row.doc.name;
    t.add({name, row.doc.type, row.doc.default_value, row.doc.unit, "poses odometry: " + row.doc.doc},
          [name, inner = row.doc.name](E& e, const std::string& v) {
            odometry::OdometrySettings check;
            try {
              odometry::odometry_settings_table().set(check, inner, v);
            } catch (const std::invalid_argument& error) {
              throw std::invalid_argument("setting '" + name + "': " + error.what());
            }
            const auto same = [&](const auto& kv) { return kv.first == inner; };
            e.odometry.erase(std::remove_if(e.odometry.begin(), e.odometry.end(), same), e.odometry.end());
            e.odometry.emplace_back(inner, v);
          },
          [get = row.get](const E& e) {
            odometry::OdometrySettings o;
            odometry::odometry_settings_table().apply(o, e.odometry);
            return get(o);
          });
  }
#endif
  t.add({"real_time", "bool", format_bool(d.real_time), "",
         "run the arm on ViSP's threaded simulator in wall-clock time (robot viper850 or afma6)"},
        [](E& e, const std::string& v) { e.real_time = parse_bool("real_time", v); },
        [](const E& e) { return format_bool(e.real_time); });
  return t;
}

// select=labels: the scenario's object as a frame's labels show it.
perception::ObjectSelection object_in(const std::vector<std::uint16_t>& labels) {
  perception::ObjectSelection selection;
  selection.mode = perception::ObjectSelection::Mode::Image;
  selection.mask.resize(labels.size());
  std::transform(labels.begin(), labels.end(), selection.mask.begin(),
                 [](std::uint16_t label) { return label == sim::kLabelObject ? 1 : 0; });
  return selection;
}

// What the simulator knows of a frame, for the metrics: visibility, distance
// to the sphere, the angular error of the camera against the ground-truth
// supervoxels. Returns the ground-truth problem, its occluders only when
// asked for (the input in ground-truth mode; the metrics need the object's).
ViewProblem record_truth(StepRecord& rec, const sim::Renderer& renderer, const EstimatorSettings& estimator,
                         bool occluders) {
  const double r_sphere = estimator.r_sphere;
  const sim::ObjectTruth truth = renderer.truth(rec.wMc, r_sphere);
  ViewProblem gt_problem = occluders ? renderer.ground_truth_problem(rec.wMc, estimator.r_seed, r_sphere)
                                     : renderer.ground_truth_object(rec.wMc, estimator.r_seed);
  rec.visible_fraction = truth.visible_fraction;
  rec.occluders_in_sphere = truth.occluders_in_sphere;
  rec.sphere_distance_error = (rec.wMc.translation() - truth.centroid).norm() - r_sphere;
  const Eigen::Vector3d gt_centroid =
      gt_problem.positions.cols() > 0 ? Eigen::Vector3d(gt_problem.positions.rowwise().mean()) : truth.centroid;
  rec.angular_error_deg = mean_angular_error_deg(gt_problem, gt_centroid, r_sphere, rec.wMc.translation());
  rec.true_centroid = truth.centroid;
  return gt_problem;
}


// The front end's output against the frame's labels and the object's true surface.
perception::PerceptionScores score(const RgbdFrame& frame, const perception::PerceptionResult& result, const sim::Renderer& renderer,
                       const perception::PerceptionSettings& settings) {
  perception::PerceptionTruth truth;
  truth.centroid = frame.object_centroid;
  truth.r_sphere = settings.r_sphere;
  truth.surface = renderer.object_surface();
  return perception::score_perception(frame, result, truth, settings);
}

// Ground truth as the loop sees it: the simulator's problem (every occluder
// in the sphere, seen or not) and, as the shown area, what a front end that
// classified every pixel right would report; no other truth.
Observation truth_observation(const RgbdFrame& frame, ViewProblem problem, const perception::PerceptionSettings& settings) {
  Observation o;
  o.wMc = frame.wMc;
  o.problem = std::move(problem);
  o.shown_area = perception::labelled_shown_area(frame, settings);
  return o;
}

// The same for frames rendered elsewhere (a live simulated sensor).
class TruthObserver final : public Observer {
 public:
  TruthObserver(const sim::Renderer& renderer, const EstimatorSettings& estimator, const perception::PerceptionSettings& settings)
      : renderer_(renderer), estimator_(estimator), settings_(settings) {}
  Observation observe(const RgbdFrame& frame) override {
    return truth_observation(frame, renderer_.ground_truth_problem(frame.wMc, estimator_.r_seed, estimator_.r_sphere),
                             settings_);
  }

 private:
  const sim::Renderer& renderer_;
  EstimatorSettings estimator_;
  perception::PerceptionSettings settings_;
};

// The pose a pose source gave, against the true one.
PoseRecord pose_record(const std::string& source, const FramePose& pose, const Eigen::Isometry3d& wMc_true) {
  PoseRecord p;
  p.source = source;
  p.status = pose.status;
  p.known = pose.ok;
  p.wMc = pose.wMc;
  p.translation_error = (pose.wMc.translation() - wMc_true.translation()).norm();
  p.rotation_error = Eigen::AngleAxisd(wMc_true.linear().transpose() * pose.wMc.linear()).angle() * 180.0 / M_PI;
  return p;
}

// A frame with a pose source's pose while the front end looks at it (and
// its scores are taken: the front end's world is that pose's); then its own
// again (the true pose) for the records, pictures and recordings.
class AtPose {
 public:
  AtPose(RgbdFrame& frame, const std::optional<FramePose>& pose) : frame_(frame), own_(frame.wMc) {
    if (pose) frame_.wMc = pose->wMc;
  }
  ~AtPose() { frame_.wMc = own_; }
  AtPose(const AtPose&) = delete;
  AtPose& operator=(const AtPose&) = delete;

 private:
  RgbdFrame& frame_;
  Eigen::Isometry3d own_;
};

// What the loop did.
void record_step(StepRecord& rec, const servo::LoopStep& step) {
  rec.times.estimate = step.estimate_s;
  rec.times.control = step.control_s;
  rec.status = step.status;
  rec.safety = step.safety;
  if (step.estimate) {
    rec.t0 = step.estimate->t0;
    rec.tf = step.estimate->tf;
    rec.iterations = step.estimate->iterations;
  }
  rec.target = step.target;
  for (const OccluderTrack& t : step.tracks) {
    if (!t.confirmed || t.points.cols() == 0) continue;
    ++rec.tracks;
    rec.fastest_track_speed = std::max(rec.fastest_track_speed, t.velocity.norm());
  }
  rec.predicted_occluders = static_cast<int>(step.predicted_occluders);
  rec.mode = step.mode;
  rec.guard = step.guard;
  rec.proposer = step.proposer;
  rec.estimator_calls = step.estimator_calls;
  for (unsigned i = 0; i < 6; ++i) rec.velocity(i) = step.velocity[i];
}

// Method hindsight's planner: the setup's lattice and step, the loop's speed limits.
sim::HindsightSettings planner_settings(const EpisodeSetup& setup) {
  sim::HindsightSettings h = setup.hindsight;
  h.max_speed = setup.loop.controller.max_linear_speed;
  h.max_turn_rate = setup.loop.controller.max_angular_speed;
  return h;
}

// The number of frames of an episode, checked before it becomes an integer
// (a setup made in code skips the settings' bounds).
long episode_frames(const EpisodeSetup& setup) {
  const double rate = setup.scenario.rate;
  if (!(std::isfinite(rate) && rate > 0.0)) {
    throw std::invalid_argument("scenario rate must be finite and positive, got " + format_number(rate));
  }
  if (!(std::isfinite(setup.duration) && setup.duration >= 0.0 && setup.duration <= kMaxEpisodeDuration)) {
    throw std::invalid_argument("episode duration must be finite, in [0, " + format_number(kMaxEpisodeDuration) +
                                "] s, got " + format_number(setup.duration));
  }
  const double frames = std::floor(setup.duration * rate + 1e-9) + 1.0;
  if (!(frames <= kMaxEpisodeFrames)) {
    throw std::invalid_argument("duration " + format_number(setup.duration) + " s at rate " + format_number(rate) +
                                " Hz: more than " + format_number(kMaxEpisodeFrames) + " frames");
  }
  return static_cast<long>(frames);
}

}  // namespace

perception::PerceptionSettings front_end_settings(const EpisodeSetup& setup) {
  perception::PerceptionSettings settings = perception::perception_settings(setup.loop.estimator.resolve(), setup.front_end);
  if (setup.perception == PerceptionMode::Labels) settings.classes = perception::PerceptionSettings::Classes::Labels;
  return settings;
}

std::string poses_word(const EpisodeSetup& setup) {
  if (setup.poses == PoseOrigin::Frame) return "simulator";
  return setup.odometry_method.empty() ? "odometry" : "odometry:" + setup.odometry_method;
}

PoseSource episode_pose_source(const EpisodeSetup& setup) {
  if (setup.poses == PoseOrigin::Frame) return {};
#ifdef OFV_LOOP_HAVE_ODOMETRY
  odometry::OdometrySettings settings;
  if (!setup.odometry_method.empty()) settings.method = odometry::parse_method("poses", setup.odometry_method);
  odometry::odometry_settings_table().apply(settings, setup.odometry);
  return odometry::odometry_pose_source(settings);
#else
  throw std::invalid_argument("setting poses = " + poses_word(setup) + " " + kNoOdometry);
#endif
}

const char* to_string(PerceptionMode mode) {
  switch (mode) {
    case PerceptionMode::Full: return "full";
    case PerceptionMode::Labels: return "labels";
    case PerceptionMode::GroundTruth: return "ground-truth";
  }
  return "?";
}
const char* to_string(ObjectSelect select) { return select == ObjectSelect::Labels ? "labels" : "auto"; }

const SettingsTable<EpisodeSetup>& episode_settings_table() {
  static const SettingsTable<EpisodeSetup> table = make_table();
  return table;
}

EpisodeSetup resolve_episode(const sim::Scenario& scenario,
                             const std::vector<std::pair<std::string, std::string>>& settings) {
  EpisodeSetup s;
  s.loop.estimator = scenario.estimator;
  s.robot = servo::parse_robot_kind(scenario.robot);
  s.duration = scenario.duration;
  // The scenario's controller section (`law` is the setting `controller`), then the settings.
  for (const auto& [k, v] : scenario.controller) episode_settings_table().set(s, k == "law" ? "controller" : k, v);
  episode_settings_table().apply(s, settings);
  s.scenario = sim::with_seed(scenario, s.seed);
  (void)servo::ViewLoop(s.loop);  // validates every loop setting
  // Valid one by one, meaningless together: every frame older than the
  // stale timeout when its command is sent, the robot would never move.
  const double age = (1.0 + s.latency) / s.scenario.rate;
  if (!s.real_time && age > s.loop.safety.stale_timeout) {
    throw std::invalid_argument("settings latency = " + std::to_string(s.latency) + " and stale_timeout = " +
                                format_number(s.loop.safety.stale_timeout) + " s: at " + format_number(s.scenario.rate) +
                                " Hz every frame is " + format_number(age) +
                                " s old when its command is sent, older than stale_timeout, and the robot would "
                                "never move; lower latency or raise stale_timeout");
  }
  if (s.loop.method == ViewMethod::Hindsight) {
    sim::check_hindsight(planner_settings(s), s.loop.estimator.resolve().r_sphere, s.duration, s.scenario.rate);
  }
  if (s.poses != PoseOrigin::Frame) {
    // The ground truth and the plan are the simulator's, poses included:
    // nothing there would read a pose odometry estimated.
    if (s.perception == PerceptionMode::GroundTruth) {
      throw std::invalid_argument("setting poses = " + poses_word(s) +
                                  " needs perception full or labels: with perception = ground-truth the loop's input "
                                  "is the simulator's, in its true camera frame, and no pose estimate would be used");
    }
    if (s.loop.method == ViewMethod::Hindsight) {
      throw std::invalid_argument("setting poses = " + poses_word(s) +
                                  " does not go with method = hindsight: the plan is followed from the true poses, "
                                  "without perception");
    }
#ifdef OFV_LOOP_HAVE_ODOMETRY
    odometry::OdometrySettings o;
    odometry::odometry_settings_table().apply(o, s.odometry);
    try {
      odometry::validate(o);
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument(std::string("odometry settings (odometry_NAME): ") + e.what());
    }
#endif
  }
  if (s.real_time && s.robot == servo::RobotKind::Camera) {
    throw std::invalid_argument("setting 'real_time' needs robot viper850 or afma6 (ViSP's threaded simulators)");
  }
  return s;
}

EpisodeOutcome run_episode(const EpisodeSetup& setup, const StepObserver& observer) {
  const sim::Scenario& scenario = setup.scenario;
  const long steps = episode_frames(setup);
  const double dt = 1.0 / scenario.rate;

  servo::ViewLoop loop(setup.loop);
  sim::Renderer renderer(scenario);
  std::unique_ptr<servo::CameraRobot> robot = servo::make_robot(setup.robot, servo::to_visp(scenario.wMc_start), setup.real_time);
  const perception::PerceptionSettings front_end = front_end_settings(setup);
  std::optional<perception::PerceptionObserver> perception;  // full, labels: made on the first frame, which may point out the object
  // Setting poses: the pose the front end and the loop get, from the
  // frames (the renderer keeps rendering from the true pose).
  const PoseSource pose_source = episode_pose_source(setup);
  const std::string poses = poses_word(setup);
  ObjectHint object;  // the object in the last frame, for the pose source

  // Method hindsight: the path planned from the whole episode, tracked: the
  // command of each frame aims at where the path is when the command's
  // period ends (one period plus the latency ahead), reached in that time.
  std::optional<sim::HindsightPlan> plan;
  double lead = 0.0;
  if (setup.loop.method == ViewMethod::Hindsight) {
    plan = sim::plan_hindsight(scenario, scenario.wMc_start, loop.estimator().r_sphere, setup.duration,
                               planner_settings(setup));
    lead = dt * (1 + setup.latency);
  }

  // Commands on their way to the robot, oldest first.
  std::deque<vpColVector> in_flight(static_cast<std::size_t>(setup.latency), vpColVector(6, 0.0));
  EpisodeOutcome outcome;
  const sim::SensorSettings& sensor = renderer.scenario().sensor;
  sim::RenderedFrame rendered;  // each frame is rendered into the memory of the one before
  for (long k = 0; k < steps; ++k) {
    StepRecord rec;
    rec.time = static_cast<double>(k) * dt;
    const vpHomogeneousMatrix wMc_visp = robot->wMc();
    const Eigen::Isometry3d wMc = servo::to_eigen(wMc_visp);
    rec.wMc = wMc;

    auto start = Clock::now();
    renderer.set_time(rec.time);
    renderer.render(wMc, k, sensor.intrinsics, sensor.noise.enabled, rendered);
    rendered.frame.timestamp = rec.time;
    rec.times.render = seconds_since(start);

    ViewProblem gt_problem =
        record_truth(rec, renderer, loop.estimator(), !plan && setup.perception == PerceptionMode::GroundTruth);
    rec.occluders_in_view = sim::occluders_seen(rendered.frame.labels);

    // The frame is as old as 1 + latency periods when its command is replaced.
    const double age = dt * (1 + setup.latency);
    std::optional<Observation> observation;
    servo::LoopStep step;
    if (plan) {
      const double ahead = rec.time + lead;
      step = loop.follow(plan->view_at(ahead), plan->centroid_at(ahead), wMc, age, dt, lead);
    } else {
      start = Clock::now();
      if (setup.perception != PerceptionMode::GroundTruth && !perception) {
        perception::PerceptionSettings settings = front_end;
        if (setup.select == ObjectSelect::Labels) settings.selection = object_in(rendered.frame.labels);
        perception.emplace(settings);
      }
      if (perception) {
        std::optional<FramePose> pose;
        if (pose_source) {
          pose = pose_source(rendered.frame, object);
          rec.pose = pose_record(poses, *pose, wMc);
        }
        const AtPose at(rendered.frame, pose);
        observation = perception->observe(rendered.frame);
        observation->pose = !pose || pose->ok ? PoseStatus::Known : PoseStatus::Unknown;
        rec.times.perception = seconds_since(start);
        object = observation->problem
                     ? object_hint(observation->problem->positions, observation->wMc, observation->support_plane)
                     : ObjectHint{};
        rec.perception = score(rendered.frame, perception->last(), renderer, front_end);
      } else {
        observation = truth_observation(rendered.frame, std::move(gt_problem), front_end);
        rec.times.perception = seconds_since(start);
      }
      observation->age = age;
      step = loop.step(*observation, dt);
    }
    record_step(rec, step);

    outcome.steps.push_back(rec);
    if (observer) {
      StepDetail detail;
      detail.frame = &rendered.frame;
      detail.observation = observation ? &*observation : nullptr;
      detail.step = &step;
      observer(rec, detail);
    }
    in_flight.push_back(step.velocity);
    if (k + 1 < steps) (void)robot->step(in_flight.front(), dt);
    in_flight.pop_front();
  }
  outcome.metrics = summarise(outcome.steps);
  if (plan) {
    HindsightBound& b = outcome.metrics.hindsight.emplace();
    b.planned = plan->bound;
    b.unlimited = plan->unlimited_bound;
    b.views = plan->lattice_views;
    b.steps = static_cast<int>(plan->times.size());
    b.step = plan->step;
    b.spacing = setup.hindsight.spacing;
    b.evaluations = plan->evaluations;
    b.plan_s = plan->seconds;
  }
  return outcome;
}

EpisodeOutcome rehearse(const EpisodeSetup& setup, const volatile std::sig_atomic_t* stop,
                        const std::function<void(const servo::RobotLoopFrame&)>& observer) {
  if (setup.robot == servo::RobotKind::Camera) {
    throw std::invalid_argument("a rehearsal needs robot viper850 or afma6 (ViSP's threaded simulators), not camera");
  }
  (void)episode_frames(setup);
  const EstimatorSettings estimator = setup.loop.estimator.resolve();
  sim::Renderer renderer(setup.scenario);
  std::unique_ptr<servo::CameraRobot> robot = servo::make_robot(setup.robot, servo::to_visp(setup.scenario.wMc_start), /*real_time=*/true);
  sim::LiveSource source(renderer, [&robot] { return servo::to_eigen(robot->wMc()); }, setup.duration);

  servo::RobotLoopOptions options;
  options.wall_clock_age = true;
  options.first_period = 1.0 / setup.scenario.rate;
  options.stop = stop;
  options.pose_source = episode_pose_source(setup);
  const std::string poses = poses_word(setup);
  perception::PerceptionSettings front_end = front_end_settings(setup);
  if (setup.perception != PerceptionMode::GroundTruth && setup.select == ObjectSelect::Labels) {
    // The first frame's labels, rendered from where the arm starts.
    sim::RenderedFrame first;
    const sim::SensorSettings& sensor = renderer.scenario().sensor;
    renderer.set_time(0.0);
    renderer.render(servo::to_eigen(robot->wMc()), 0, sensor.intrinsics, sensor.noise.enabled, first);
    front_end.selection = object_in(first.frame.labels);
  }
  TruthObserver truth(renderer, estimator, front_end);
  std::optional<perception::PerceptionObserver> perception;
  if (setup.perception != PerceptionMode::GroundTruth) perception.emplace(front_end);
  Observer& observer_of_frames = perception ? static_cast<Observer&>(*perception) : truth;

  EpisodeOutcome outcome;
  (void)servo::run_on_robot(source, observer_of_frames, *robot, setup.loop, options, [&](const servo::RobotLoopFrame& f) {
    StepRecord rec;
    rec.time = f.frame->timestamp;
    rec.wMc = f.frame->wMc;
    (void)record_truth(rec, renderer, estimator, false);  // the renderer is still at this frame's time
    rec.occluders_in_view = sim::occluders_seen(f.frame->labels);
    if (f.pose) rec.pose = pose_record(poses, *f.pose, rec.wMc);
    if (perception && f.pose) {
      // Scored as the front end saw it: with the pose source's pose.
      RgbdFrame seen = *f.frame;
      seen.wMc = f.pose->wMc;
      rec.perception = score(seen, perception->last(), renderer, front_end);
    } else if (perception) {
      rec.perception = score(*f.frame, perception->last(), renderer, front_end);
    }
    rec.times.render = f.source_s;
    rec.times.perception = f.perception_s;
    record_step(rec, *f.step);
    outcome.steps.push_back(rec);
    if (observer) observer(f);
  });
  outcome.metrics = summarise(outcome.steps);
  return outcome;
}

EpisodeRunner simulation_runner() {
  return [](const EpisodeSpec& spec) {
    auto settings = spec.variant.settings;
    // Seed k of a scenario is the same world for every variant.
    settings.emplace_back("seed", std::to_string(spec.seed));
    const EpisodeSetup setup = resolve_episode(sim::load_scenario(spec.scenario_path), settings);
    EpisodeOutcome outcome = run_episode(setup);
    outcome.settings = episode_settings_table().values(setup);
    return outcome;
  };
}

}  // namespace ofv
