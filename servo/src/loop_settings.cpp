// The loop's settings by name (loop_settings_table()).
#include "ofv/servo/view_loop.h"

#include "ofv/estimator_settings.h"

#include <cmath>
#include <sstream>
#include <stdexcept>
#include <string>

namespace ofv::servo {

namespace {

// `none`, or xmin,ymin,zmin,xmax,ymax,zmax [m].
Eigen::AlignedBox3d parse_workspace(const std::string& value) {
  if (value == "none") return {};
  std::istringstream in(value);
  double v[6];
  char comma = ',';
  for (int i = 0; i < 6; ++i) {
    if ((i > 0 && !(in >> comma)) || comma != ',' || !(in >> v[i]) || !std::isfinite(v[i])) {
      throw std::invalid_argument("setting 'workspace' must be none or six numbers xmin,ymin,zmin,xmax,ymax,zmax, got \"" +
                                  value + "\"");
    }
  }
  in >> std::ws;
  const Eigen::AlignedBox3d box(Eigen::Vector3d(v[0], v[1], v[2]), Eigen::Vector3d(v[3], v[4], v[5]));
  if (!in.eof() || box.isEmpty()) {
    throw std::invalid_argument("setting 'workspace' must be none or a non-empty box xmin,ymin,zmin,xmax,ymax,zmax, got \"" +
                                value + "\"");
  }
  return box;
}

// The text parse_workspace() reads back.
std::string workspace_text(const Eigen::AlignedBox3d& box) {
  if (box.isEmpty()) return "none";
  std::string out;
  for (const Eigen::Vector3d& corner : {box.min(), box.max()}) {
    for (int a = 0; a < 3; ++a) out += (out.empty() ? "" : ",") + format_number(corner(a));
  }
  return out;
}

SettingsTable<LoopSettings> make_table() {
  using L = LoopSettings;
  const LoopSettings d;
  SettingsTable<L> t;
  t.include(estimator_settings_table(), [](auto& l) -> auto& { return l.estimator; });
  t.add({"method", "estimator | static | initial_view | sampling | hindsight", to_string(d.method), "",
         "how the target view is chosen: the occlusion-free view, or a baseline; hindsight: the best path planned "
         "from the simulator's knowledge of the whole episode (the limit; simulation only)"},
        [](L& l, const std::string& v) {
          l.method = parse_word<ViewMethod>("method", v,
                                            {{"estimator", ViewMethod::Estimator},
                                             {"static", ViewMethod::Static},
                                             {"initial_view", ViewMethod::InitialView},
                                             {"sampling", ViewMethod::Sampling},
                                             {"hindsight", ViewMethod::Hindsight}});
        },
        [](const L& l) { return std::string(to_string(l.method)); });
  t.add({"sampling_candidates", "integer in [1, 1000000]", std::to_string(d.sampling.candidates), "",
         "candidate views on the sphere of method=sampling (Fibonacci lattice), 1 to 1e6"},
        [](L& l, const std::string& v) {
          l.sampling.candidates = static_cast<int>(parse_integer("sampling_candidates", v, 1, 1000000));
        },
        [](const L& l) { return std::to_string(l.sampling.candidates); });
  t.add({"sampling_occluder_radius", "number in (0, 1]", format_number(d.sampling.occluder_radius), "m",
         "method=sampling: an occluder point blocks lines of sight passing closer than this"},
        [](L& l, const std::string& v) {
          l.sampling.occluder_radius = parse_number("sampling_occluder_radius", v, 0.0, 1.0, true);
        },
        [](const L& l) { return format_number(l.sampling.occluder_radius); });
  t.add({"controller", "sphere | pbvs", d.controller.law == ControllerSettings::Law::Sphere ? "sphere" : "pbvs", "",
         "sphere: FeatureSphereView, along the sphere with the object centred; pbvs: straight to the target pose"},
        [](L& l, const std::string& v) {
          l.controller.law = parse_word<ControllerSettings::Law>(
              "controller", v, {{"sphere", ControllerSettings::Law::Sphere}, {"pbvs", ControllerSettings::Law::Pbvs}});
        },
        [](const L& l) { return std::string(l.controller.law == ControllerSettings::Law::Sphere ? "sphere" : "pbvs"); });
  t.add({"gain", "number in (0, 100]", format_number(d.controller.gain), "1/s",
         "lambda: the error decays as exp(-gain t) until the speed limits bind"},
        [](L& l, const std::string& v) { l.controller.gain = parse_number("gain", v, 0.0, 100.0, true); },
        [](const L& l) { return format_number(l.controller.gain); });
  t.add({"adaptive_gain", "bool", format_bool(d.controller.adaptive_gain), "",
         "twice the gain near zero error, the gain far away (vpAdaptiveGain)"},
        [](L& l, const std::string& v) { l.controller.adaptive_gain = parse_bool("adaptive_gain", v); },
        [](const L& l) { return format_bool(l.controller.adaptive_gain); });
  t.add({"max_linear_speed", "number in (0, 10]", format_number(d.controller.max_linear_speed), "m/s",
         "the controller scales its whole twist down until the linear velocity is within this (rotation alike: C stays centred); the safety filter enforces it"},
        [](L& l, const std::string& v) {
          l.controller.max_linear_speed = l.safety.max_linear_speed = parse_number("max_linear_speed", v, 0.0, 10.0, true);
        },
        [](const L& l) { return format_number(l.controller.max_linear_speed); });
  t.add({"max_angular_speed", "number in (0, 20]", format_number(d.controller.max_angular_speed), "rad/s",
         "the controller scales its whole twist down until the angular velocity is within this (translation alike); the safety filter enforces it"},
        [](L& l, const std::string& v) {
          l.controller.max_angular_speed = l.safety.max_angular_speed =
              parse_number("max_angular_speed", v, 0.0, 20.0, true);
        },
        [](const L& l) { return format_number(l.controller.max_angular_speed); });
  t.add({"target_filter", "number in [0, 10]", format_number(d.controller.target_filter), "s",
         "time constant of a low-pass on the target position; 0 = off"},
        [](L& l, const std::string& v) { l.controller.target_filter = parse_number("target_filter", v, 0.0, 10.0, false); },
        [](const L& l) { return format_number(l.controller.target_filter); });
  t.add({"target_hysteresis", "bool", format_bool(d.target_hysteresis), "",
         "while t0 is occluded, continue from the previous target (warm start) instead of re-estimating from t0"},
        [](L& l, const std::string& v) { l.target_hysteresis = parse_bool("target_hysteresis", v); },
        [](const L& l) { return format_bool(l.target_hysteresis); });
  t.add({"anticipation", "off | predict", to_string(d.anticipation.mode), "",
         "off: the paper's reactive view; predict: also keep clear of where tracked occluders will be over the horizon"},
        [](L& l, const std::string& v) {
          l.anticipation.mode = parse_word<Anticipation>("anticipation", v,
                                                         {{"off", Anticipation::Off}, {"predict", Anticipation::Predict}});
        },
        [](const L& l) { return std::string(to_string(l.anticipation.mode)); });
  t.add({"anticipation_horizon", "number in (0, 5]", format_number(d.anticipation.horizon), "s",
         "anticipation=predict: how far ahead the occluders' motion is followed"},
        [](L& l, const std::string& v) {
          l.anticipation.horizon = parse_number("anticipation_horizon", v, 0.0, 5.0, true);
        },
        [](const L& l) { return format_number(l.anticipation.horizon); });
  t.add({"anticipation_samples", "integer in [1, 10]", std::to_string(d.anticipation.samples), "",
         "anticipation=predict: predicted copies of a moving occluder over the horizon, 1 to 10"},
        [](L& l, const std::string& v) {
          l.anticipation.samples = static_cast<int>(parse_integer("anticipation_samples", v, 1, 10));
        },
        [](const L& l) { return std::to_string(l.anticipation.samples); });
  t.add({"anticipation_min_speed", "number in [0, 10]", format_number(d.anticipation.min_speed), "m/s",
         "anticipation=predict: occluders tracked slower than this are taken as still"},
        [](L& l, const std::string& v) {
          l.anticipation.min_speed = parse_number("anticipation_min_speed", v, 0.0, 10.0, false);
        },
        [](const L& l) { return format_number(l.anticipation.min_speed); });
  t.add({"track_link_distance", "number in (0, 1]", format_number(d.tracker.link_distance), "m",
         "occluder tracks: points closer than this are one occluder"},
        [](L& l, const std::string& v) {
          l.tracker.link_distance = parse_number("track_link_distance", v, 0.0, 1.0, true);
        },
        [](const L& l) { return format_number(l.tracker.link_distance); });
  t.add({"track_gate", "number in (0, 10]", format_number(d.tracker.gate), "m",
         "occluder tracks: largest distance of an occluder's centroid from its track's prediction"},
        [](L& l, const std::string& v) { l.tracker.gate = parse_number("track_gate", v, 0.0, 10.0, true); },
        [](const L& l) { return format_number(l.tracker.gate); });
  t.add({"track_accel_noise", "number in (0, 1000]", format_number(d.tracker.accel_noise), "m/s^2",
         "occluder tracks: white-noise acceleration of the constant-velocity Kalman filter"},
        [](L& l, const std::string& v) {
          l.tracker.accel_noise = parse_number("track_accel_noise", v, 0.0, 1000.0, true);
        },
        [](const L& l) { return format_number(l.tracker.accel_noise); });
  t.add({"track_measurement_noise", "number in (0, 1]", format_number(d.tracker.measurement_noise), "m",
         "occluder tracks: standard deviation of an occluder's measured centroid"},
        [](L& l, const std::string& v) {
          l.tracker.measurement_noise = parse_number("track_measurement_noise", v, 0.0, 1.0, true);
        },
        [](const L& l) { return format_number(l.tracker.measurement_noise); });
  t.add({"track_confirm_hits", "integer in [1, 1000]", std::to_string(d.tracker.confirm_hits), "",
         "occluder tracks: frames seen before a track is used, 1 to 1000"},
        [](L& l, const std::string& v) {
          l.tracker.confirm_hits = static_cast<int>(parse_integer("track_confirm_hits", v, 1, 1000));
        },
        [](const L& l) { return std::to_string(l.tracker.confirm_hits); });
  t.add({"track_max_misses", "integer in [0, 1000]", std::to_string(d.tracker.max_misses), "",
         "occluder tracks: frames unseen before a track is dropped, 0 to 1000"},
        [](L& l, const std::string& v) {
          l.tracker.max_misses = static_cast<int>(parse_integer("track_max_misses", v, 0, 1000));
        },
        [](const L& l) { return std::to_string(l.tracker.max_misses); });
  t.add({"retreat_drop", "number in [0, 1]", format_number(d.retreat.drop), "",
         "the look-ahead's loss: where the way to the target would hide this fraction more of the object, the camera "
         "climbs or holds (look_ahead); above 0, an object lost within 0.5 s of the view that showed the most also "
         "sends the camera back there, to hold that view once it finds the object again until t0 is clear; 0 (both off) to 1"},
        [](L& l, const std::string& v) { l.retreat.drop = parse_number("retreat_drop", v, 0.0, 1.0, false); },
        [](const L& l) { return format_number(l.retreat.drop); });
  t.add({"look_ahead", "bool", format_bool(d.retreat.look_ahead), "",
         "with retreat_drop > 0, until t0 has been clear (what hides the object was there from the start): where, on "
         "its way to the target, the occluders would hide retreat_drop more of the object (as far as it travels before "
         "it could stop), the camera climbs to a nearby view that sees clearly more, or holds"},
        [](L& l, const std::string& v) { l.retreat.look_ahead = parse_bool("look_ahead", v); },
        [](const L& l) { return format_bool(l.retreat.look_ahead); });
  t.add({"look_ahead_margin", "number in [0, 1]", format_number(d.retreat.climb.margin), "",
         "look_ahead: a nearby view the camera climbs to must see this fraction more of the object than the current one, 0 to 1"},
        [](L& l, const std::string& v) {
          l.retreat.climb.margin = parse_number("look_ahead_margin", v, 0.0, 1.0, false);
        },
        [](const L& l) { return format_number(l.retreat.climb.margin); });
  t.add({"max_linear_accel", "number in (0, 100]", format_number(d.safety.max_linear_accel), "m/s^2",
         "safety filter: largest change of the linear velocity"},
        [](L& l, const std::string& v) { l.safety.max_linear_accel = parse_number("max_linear_accel", v, 0.0, 100.0, true); },
        [](const L& l) { return format_number(l.safety.max_linear_accel); });
  t.add({"max_angular_accel", "number in (0, 1000]", format_number(d.safety.max_angular_accel), "rad/s^2",
         "safety filter: largest change of the angular velocity"},
        [](L& l, const std::string& v) {
          l.safety.max_angular_accel = parse_number("max_angular_accel", v, 0.0, 1000.0, true);
        },
        [](const L& l) { return format_number(l.safety.max_angular_accel); });
  t.add({"stale_timeout", "number in (0, 60]", format_number(d.safety.stale_timeout), "s",
         "safety filter: a frame older than this when its command is sent stops the robot"},
        [](L& l, const std::string& v) { l.safety.stale_timeout = parse_number("stale_timeout", v, 0.0, 60.0, true); },
        [](const L& l) { return format_number(l.safety.stale_timeout); });
  t.add({"workspace", "none | xmin,ymin,zmin,xmax,ymax,zmax", "none", "m",
         "safety filter: the camera stays inside this box (world frame)"},
        [](L& l, const std::string& v) { l.safety.workspace = parse_workspace(v); },
        [](const L& l) { return workspace_text(l.safety.workspace); });
  return t;
}

}  // namespace

const SettingsTable<LoopSettings>& loop_settings_table() {
  static const SettingsTable<LoopSettings> table = make_table();
  return table;
}

const char* to_string(Anticipation a) { return a == Anticipation::Off ? "off" : "predict"; }

}  // namespace ofv::servo
