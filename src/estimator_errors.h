// Usage-error helpers shared by the estimator's sources (not installed).
#pragma once

#include <Eigen/Core>

#include <sstream>
#include <stdexcept>
#include <string>

namespace ofv::detail {

/// Invalid input: the message names the field and the value (CONVENTIONS.md).
[[noreturn]] inline void usage_error(const std::string& what) {
  throw std::invalid_argument(what);
}

/// A value as it must be quoted in a message: round-trip precision.
inline std::string format_value(double v) {
  std::ostringstream s;
  s.precision(17);
  s << v;
  return s.str();
}

inline std::string format_value(const Eigen::Vector3d& p) {
  return "[" + format_value(p.x()) + ", " + format_value(p.y()) + ", " + format_value(p.z()) + "]";
}

}  // namespace ofv::detail
