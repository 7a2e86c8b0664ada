/**
 * \file constants.h
 * \brief Mathematical constants shared by the ofv libraries (no dependencies).
 */
#pragma once

namespace ofv {

/// \brief pi, to double precision (use instead of M_PI, which is not standard C++).
inline constexpr double kPi = 3.14159265358979323846;

}  // namespace ofv
