/**
 * \file safety.h
 * \brief The last filter before a velocity reaches real hardware.
 */
#pragma once

#include "ofv/servo/controller.h"
#include "ofv/servo/loop_status.h"

#include <Eigen/Geometry>
#include <visp3/core/vpColVector.h>
#include <visp3/core/vpHomogeneousMatrix.h>

namespace ofv::servo {

/// \brief Limits of SafetyFilter (camera frame for velocities, world frame for the workspace).
struct SafetySettings {
  /// [m/s]; by default the controller's limit, which the filter enforces whatever computed the command.
  double max_linear_speed = ControllerSettings{}.max_linear_speed;
  double max_angular_speed = ControllerSettings{}.max_angular_speed;  ///< [rad/s], as the controller's
  /// [m/s^2]: reaching 0.5 m/s from rest takes 62 ms. The view controller
  /// asks for up to 12-30 m/s^2 in the frame an occluder appears; this cuts
  /// those steps and costs the built-in scenarios at most 0.003 of visible
  /// fraction. Set it to your arm's limit at the tool.
  double max_linear_accel = 8.0;
  double max_angular_accel = 24.0;   ///< [rad/s^2]
  /// The camera must stay inside this box (world frame) [m]; motion that
  /// would leave it is removed. Empty box = no bound.
  Eigen::AlignedBox3d workspace;
  double stale_timeout = 0.2;        ///< frames older than this stop the robot [s]
};

/// \brief Throws std::invalid_argument naming a limit that is not finite and positive.
void validate(const SafetySettings& settings);


/**
 * \brief Speed, acceleration and workspace limits, and zero velocity when
 *        the object is lost, the frame is stale or its camera pose unknown.
 */
class SafetyFilter {
 public:
  /// \throws std::invalid_argument naming a limit that is not finite and positive.
  explicit SafetyFilter(const SafetySettings& settings = {});
  /**
   * \param v camera twist asked for (camera frame).
   * \param wMc current camera pose.
   * \param dt period [s].
   * \param object_tracked false when perception lost the object.
   * \param frame_age age of the frame the command comes from [s].
   * \param pose_known false when the frame's camera pose is not known
   *        (ofv::Observation::pose): stop, SafetyAction::PoseUnknown.
   * \return the twist to send.
   */
  [[nodiscard]] vpColVector filter(const vpColVector& v, const vpHomogeneousMatrix& wMc, double dt,
                                   bool object_tracked, double frame_age, bool pose_known = true);
  /// \brief What the filter did to the last command.
  [[nodiscard]] SafetyAction last_action() const { return action_; }
  /// \brief Forgets the previous command (the robot is at rest).
  void reset() { previous_ = vpColVector(6, 0.0); }
  /// \brief The limits it was constructed with.
  [[nodiscard]] const SafetySettings& settings() const { return settings_; }

 private:
  SafetySettings settings_;
  vpColVector previous_ = vpColVector(6, 0.0);
  SafetyAction action_ = SafetyAction::None;
};

}  // namespace ofv::servo

/// \cond OFV_OLD_NAMES
// The names of ofv 0.1, kept for one release: use ofv::servo::.
namespace ofv {
using SafetyFilter [[deprecated("use ofv::servo::SafetyFilter")]] = servo::SafetyFilter;
using SafetySettings [[deprecated("use ofv::servo::SafetySettings")]] = servo::SafetySettings;
using servo::validate;
}  // namespace ofv
/// \endcond
