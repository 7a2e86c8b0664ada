// Estimator settings: presets, validation (ESTIMATOR-SPEC.md §4 `preset`, §7)
// and the enumeration words of scene files and the command line.
#include "estimator_errors.h"
#include "ofv/estimator.h"

#include <cmath>

namespace ofv {

using detail::format_value;
using detail::usage_error;

namespace {

void require_positive(const char* name, double value) {
  if (!std::isfinite(value) || value <= 0.0) {
    usage_error(std::string("parameter '") + name + "' must be finite and positive, got " +
                format_value(value));
  }
}

}  // namespace

void validate(const EstimatorSettings& s) {
  require_positive("r_seed", s.r_seed);
  require_positive("r_sphere", s.r_sphere);
  require_positive("clearance", s.clearance);
  require_positive("push_radius", s.push_radius);
  require_positive("step", s.step);
  if (s.max_iterations < 0) {
    usage_error("parameter 'max_iterations' must be a non-negative integer, got " +
                std::to_string(s.max_iterations));
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

}  // namespace ofv
