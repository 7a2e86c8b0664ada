// The estimator's settings table.
#include "ofv/estimator_settings.h"

#include <climits>
#include <limits>

namespace ofv {

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
        });
  t.add({"r_seed", "number > 0", format_number(d.r_seed), "m", "supervoxel seed resolution R_seed"},
        [](P& p, const std::string& v) { p.r_seed = parse_number("r_seed", v, -kInf, kInf, false); });
  t.add({"r_sphere", "number > 0", format_number(d.r_sphere), "m", "radius of the solution sphere around the object"},
        [](P& p, const std::string& v) { p.r_sphere = parse_number("r_sphere", v, -kInf, kInf, false); });
  t.add({"initial_view", "spherical_mean | vector_mean", to_string(d.initial_view), "",
         "how t0 averages the normals-to-sphere rays"},
        [](P& p, const std::string& v) {
          p.initial_view = parse_word<InitialView>(
              "initial_view", v, {{"spherical_mean", InitialView::SphericalMean}, {"vector_mean", InitialView::VectorMean}});
        });
  t.add({"clearance", "number > 0 | r_seed | r_sphere", format_number(d.clearance), "m",
         "the view is clear when no projected occlusion point is closer (paper: r_seed)"},
        [](P& p, const std::string& v) { p.clearance = length(p, "clearance", v); });
  t.add({"push_radius", "number > 0 | r_seed | r_sphere", format_number(d.push_radius), "m",
         "projected points closer than this push the view (paper: r_sphere; r_seed is the other reading)"},
        [](P& p, const std::string& v) { p.push_radius = length(p, "push_radius", v); });
  t.add({"push_weighting", "sum | inverse_distance", to_string(d.push_weighting), "",
         "sum of the pushes, or each divided by its squared length"},
        [](P& p, const std::string& v) {
          p.push_weighting = parse_word<PushWeighting>(
              "push_weighting", v, {{"sum", PushWeighting::Sum}, {"inverse_distance", PushWeighting::InverseDistance}});
        });
  t.add({"step", "number > 0 | r_seed | r_sphere", format_number(d.step), "m",
         "length of one push on the tangent plane (paper: r_seed)"},
        [](P& p, const std::string& v) { p.step = length(p, "step", v); });
  t.add({"max_iterations", "integer >= 0", std::to_string(d.max_iterations), "",
         "push steps before giving up with the best visited view"},
        [](P& p, const std::string& v) { p.max_iterations = static_cast<int>(parse_integer("max_iterations", v, 0, INT_MAX)); });
  t.add({"warm_start", "bool", format_bool(d.warm_start), "", "start from the previous frame's view instead of t0"},
        [](P& p, const std::string& v) { p.warm_start = parse_bool("warm_start", v); });
  return t;
}

}  // namespace

const SettingsTable<EstimatorParams>& estimator_settings_table() {
  static const SettingsTable<EstimatorParams> table = make_table();
  return table;
}

}  // namespace ofv
