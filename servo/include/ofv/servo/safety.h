/**
 * \file safety.h
 * \brief The last filter before a velocity reaches real hardware.
 */
#pragma once

#include <Eigen/Geometry>
#include <visp3/core/vpColVector.h>
#include <visp3/core/vpHomogeneousMatrix.h>

namespace ofv {

/// \brief Limits of SafetyFilter (camera frame for velocities, world frame for the workspace).
struct SafetySettings {
  double max_linear_speed = 0.25;    ///< [m/s]
  double max_angular_speed = 0.8;    ///< [rad/s]
  double max_linear_accel = 1.0;     ///< [m/s^2]
  double max_angular_accel = 3.0;    ///< [rad/s^2]
  /// The camera must stay inside this box (world frame) [m]; motion that
  /// would leave it is removed. Empty box = no bound.
  Eigen::AlignedBox3d workspace;
  double stale_timeout = 0.2;        ///< frames older than this stop the robot [s]
};

/**
 * \brief Speed, acceleration and workspace limits, and zero velocity when
 *        the object is lost or the frame is stale.
 */
class SafetyFilter {
 public:
  explicit SafetyFilter(const SafetySettings& settings = {});
  /**
   * \param v camera twist asked for (camera frame).
   * \param wMc current camera pose.
   * \param dt period [s].
   * \param object_tracked false when perception lost the object.
   * \param frame_age age of the frame the command comes from [s].
   * \return the twist to send.
   */
  [[nodiscard]] vpColVector filter(const vpColVector& v, const vpHomogeneousMatrix& wMc, double dt,
                                   bool object_tracked, double frame_age);
  /// \brief Why the last command was changed ("" when it passed untouched).
  [[nodiscard]] const char* last_reason() const { return reason_; }

 private:
  SafetySettings settings_;
  vpColVector previous_ = vpColVector(6, 0.0);
  const char* reason_ = "";
};

}  // namespace ofv
