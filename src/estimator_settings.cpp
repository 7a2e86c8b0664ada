// Estimator settings: presets, validation (ESTIMATOR-SPEC.md §4 `preset`, §7),
// the enumeration words of scene files and the command line, and the table of
// the settings by name.
#include "estimator_errors.h"
#include "ofv/estimator.h"
#include "ofv/estimator_settings.h"

#include <climits>
#include <cmath>
#include <limits>

namespace ofv {

using detail::format_value;
using detail::usage_error;

namespace {

void require_positive(const char* name, double value) {
  if (!std::isfinite(value) || value <= 0.0 || value > kMaxLength) {
    usage_error(std::string("parameter '") + name + "' must be positive and at most " + format_value(kMaxLength) +
                " m, got " + format_value(value));
  }
}

}  // namespace

void validate(const EstimatorSettings& s) {
  require_positive("r_seed", s.r_seed);
  require_positive("r_sphere", s.r_sphere);
  require_positive("clearance", s.clearance);
  require_positive("push_radius", s.push_radius);
  require_positive("step", s.step);
  if (s.max_iterations < 0 || s.max_iterations > kMaxIterations) {
    usage_error("parameter 'max_iterations' must be an integer in [0, 100000000], got " + std::to_string(s.max_iterations));
  }
  if (!(s.time_budget > 0.0 && s.time_budget <= 3600.0)) {
    usage_error("parameter 'time_budget' must be in (0, 3600] s, got " + format_value(s.time_budget));
  }
}

EstimatorSettings EstimatorParams::resolve() const {
  EstimatorSettings s;
  s.r_seed = r_seed.value_or(s.r_seed);
  s.r_sphere = r_sphere.value_or(s.r_sphere);
  switch (preset) {
    case Preset::Paper:
      s.clearance = s.r_seed;
      s.push_radius = s.r_sphere;
      s.step = s.r_seed;
      s.max_iterations = 500;
      break;
    case Preset::AuthorsCode:
      s.clearance = 2.0 * s.r_seed;
      s.push_radius = s.r_sphere;
      s.step = s.r_seed / 2.0;
      s.max_iterations = 50;
      break;
  }
  s.initial_view = initial_view.value_or(s.initial_view);
  s.clearance = clearance.value_or(s.clearance);
  s.push_radius = push_radius.value_or(s.push_radius);
  s.push_weighting = push_weighting.value_or(s.push_weighting);
  s.step = step.value_or(s.step);
  s.max_iterations = max_iterations.value_or(s.max_iterations);
  s.warm_start = warm_start.value_or(s.warm_start);
  s.time_budget = time_budget.value_or(s.time_budget);
  validate(s);
  return s;
}

const char* to_string(InitialView v) {
  return v == InitialView::SphericalMean ? "spherical_mean" : "vector_mean";
}
const char* to_string(PushWeighting v) {
  return v == PushWeighting::Sum ? "sum" : "inverse_distance";
}
const char* to_string(Preset v) { return v == Preset::Paper ? "paper" : "authors_code"; }
const char* to_string(ViewStatus v) {
  switch (v) {
    case ViewStatus::Converged: return "converged";
    case ViewStatus::NotConverged: return "not_converged";
    case ViewStatus::OutOfTime: return "out_of_time";
    case ViewStatus::NoOccluders: return "no_occluders";
    case ViewStatus::NoSupervoxels: return "no_supervoxels";
  }
  return "?";
}
const char* to_string(InitialViewUsed v) {
  switch (v) {
    case InitialViewUsed::SphericalMean: return "spherical_mean";
    case InitialViewUsed::VectorMean: return "vector_mean";
    case InitialViewUsed::Camera: return "camera";
  }
  return "?";
}

std::optional<InitialView> parse_initial_view(const std::string& word) {
  if (word == "spherical_mean") return InitialView::SphericalMean;
  if (word == "vector_mean") return InitialView::VectorMean;
  return std::nullopt;
}
std::optional<PushWeighting> parse_push_weighting(const std::string& word) {
  if (word == "sum") return PushWeighting::Sum;
  if (word == "inverse_distance") return PushWeighting::InverseDistance;
  return std::nullopt;
}
std::optional<Preset> parse_preset(const std::string& word) {
  if (word == "paper") return Preset::Paper;
  if (word == "authors_code") return Preset::AuthorsCode;
  return std::nullopt;
}

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// A length: a number, or `r_seed` / `r_sphere` meaning that radius as set so far.
double length(const EstimatorParams& p, const std::string& name, const std::string& value) {
  const EstimatorSettings defaults;
  if (value == "r_seed") return p.r_seed.value_or(defaults.r_seed);
  if (value == "r_sphere") return p.r_sphere.value_or(defaults.r_sphere);
  return parse_number(name, value, -kInf, kInf, false);  // resolve() checks the range (spec §7)
}

SettingsTable<EstimatorParams> make_table() {
  using P = EstimatorParams;
  const EstimatorSettings d;
  SettingsTable<P> t;
  t.add({"preset", "paper | authors_code", to_string(Preset::Paper), "",
         "named set applied before explicit settings; authors_code: step = r_seed/2, clearance = 2 r_seed, "
         "max_iterations = 50"},
        [](P& p, const std::string& v) {
          p.preset = parse_word<Preset>("preset", v, {{"paper", Preset::Paper}, {"authors_code", Preset::AuthorsCode}});
        },
        [](const P& p) { return std::string(to_string(p.preset)); });
  t.add({"r_seed", "number in (0, 1e4]", format_number(d.r_seed), "m", "supervoxel seed resolution R_seed"},
        [](P& p, const std::string& v) { p.r_seed = parse_number("r_seed", v, -kInf, kInf, false); },
        [](const P& p) { return format_number(p.resolve().r_seed); });
  t.add({"r_sphere", "number in (0, 1e4]", format_number(d.r_sphere), "m", "radius of the solution sphere around the object"},
        [](P& p, const std::string& v) { p.r_sphere = parse_number("r_sphere", v, -kInf, kInf, false); },
        [](const P& p) { return format_number(p.resolve().r_sphere); });
  t.add({"initial_view", "spherical_mean | vector_mean", to_string(d.initial_view), "",
         "how t0 averages the normals-to-sphere rays"},
        [](P& p, const std::string& v) {
          p.initial_view = parse_word<InitialView>(
              "initial_view", v, {{"spherical_mean", InitialView::SphericalMean}, {"vector_mean", InitialView::VectorMean}});
        },
        [](const P& p) { return std::string(to_string(p.resolve().initial_view)); });
  t.add({"clearance", "number in (0, 1e4] | r_seed | r_sphere", format_number(d.clearance), "m",
         "the view is clear when no projected occlusion point is closer (paper: r_seed)"},
        [](P& p, const std::string& v) { p.clearance = length(p, "clearance", v); },
        [](const P& p) { return format_number(p.resolve().clearance); });
  t.add({"push_radius", "number in (0, 1e4] | r_seed | r_sphere", format_number(d.push_radius), "m",
         "projected points closer than this push the view (paper: r_sphere; r_seed is the other reading)"},
        [](P& p, const std::string& v) { p.push_radius = length(p, "push_radius", v); },
        [](const P& p) { return format_number(p.resolve().push_radius); });
  t.add({"push_weighting", "sum | inverse_distance", to_string(d.push_weighting), "",
         "sum of the pushes, or each divided by its squared length"},
        [](P& p, const std::string& v) {
          p.push_weighting = parse_word<PushWeighting>(
              "push_weighting", v, {{"sum", PushWeighting::Sum}, {"inverse_distance", PushWeighting::InverseDistance}});
        },
        [](const P& p) { return std::string(to_string(p.resolve().push_weighting)); });
  t.add({"step", "number in (0, 1e4] | r_seed | r_sphere", format_number(d.step), "m",
         "length of one push on the tangent plane (paper: r_seed)"},
        [](P& p, const std::string& v) { p.step = length(p, "step", v); },
        [](const P& p) { return format_number(p.resolve().step); });
  t.add({"max_iterations", "integer in [0, 100000000]", std::to_string(d.max_iterations), "",
         "push steps before giving up with the best visited view"},
        [](P& p, const std::string& v) { p.max_iterations = static_cast<int>(parse_integer("max_iterations", v, 0, kMaxIterations)); },
        [](const P& p) { return std::to_string(p.resolve().max_iterations); });
  t.add({"warm_start", "bool", format_bool(d.warm_start), "", "start from the previous frame's view instead of t0"},
        [](P& p, const std::string& v) { p.warm_start = parse_bool("warm_start", v); },
        [](const P& p) { return format_bool(p.resolve().warm_start); });
  t.add({"time_budget", "number in (0, 3600]", format_number(d.time_budget), "s",
         "wall time one estimate may take (ofv's bound, not the spec's): then the best visited view, status "
         "out_of_time; up to 3600"},
        [](P& p, const std::string& v) { p.time_budget = parse_number("time_budget", v, 0.0, 3600.0, true); },
        [](const P& p) { return format_number(p.resolve().time_budget); });
  return t;
}

}  // namespace

const SettingsTable<EstimatorParams>& estimator_settings_table() {
  static const SettingsTable<EstimatorParams> table = make_table();
  return table;
}

}  // namespace ofv
