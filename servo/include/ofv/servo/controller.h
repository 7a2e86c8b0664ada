/**
 * \file controller.h
 * \brief The view controller: an eye-in-hand velocity law that drives the
 *        camera to the occlusion-free view, re-targeted every frame.
 */
#pragma once

#include "ofv/servo/feature_sphere_view.h"

#include <Eigen/Core>
#include <visp3/core/vpColVector.h>
#include <visp3/core/vpHomogeneousMatrix.h>

#include <memory>
#include <optional>

namespace ofv::servo {

/// \brief Settings of ViewController. Speeds in the camera frame.
struct ControllerSettings {
  /// \brief The velocity law.
  enum class Law {
    Pbvs,    ///< vpFeatureTranslation(cdMc) + vpFeatureThetaU(cdRc): straight line to the target pose
    Sphere,  ///< FeatureSphereView: along the sphere, object centred
  };
  Law law = Law::Sphere;  ///< the velocity law (setting `controller`)
  /// lambda [1/s]: the error decays as exp(-gain t) until the speed limits bind.
  /// 4 recovers from a hand entering the view in well under a second at 30 Hz.
  double gain = 4.0;
  bool adaptive_gain = true;     ///< vpAdaptiveGain: 2 gain at zero error down to gain far away (slope 30)
  double max_linear_speed = 0.5;   ///< [m/s]: the linear part is scaled down to this
  double max_angular_speed = 1.5;  ///< [rad/s]: the angular part is scaled down to this
  /// First-order low-pass on the target position, time constant [s]; 0 = off.
  /// Smooths a target that jumps between frames (a flickering occluder).
  double target_filter = 0.0;
};

/// \brief Throws std::invalid_argument naming the field and value when a setting is out of range.
void validate(const ControllerSettings& settings);

/**
 * \brief Computes the camera velocity towards a view on the sphere, one frame
 *        at a time; the desired feature is re-set at every call.
 *
 * One vpServo task (eye-in-hand, interaction matrix of the current
 * features), made once as ViSP's tutorials do: its features
 * (FeatureSphereView, or vpFeatureTranslation and vpFeatureThetaU for
 * PBVS) are built again from each frame's pose and target, its gain set
 * from the error, then computeControlLaw(). Movable, not copyable (the task
 * points to its features).
 *
 * Never returns a non-finite or over-limit command: invalid inputs give zero.
 */
class ViewController {
 public:
  /// \throws std::invalid_argument naming the field and value when a setting is out of range.
  explicit ViewController(const ControllerSettings& settings = {});
  ~ViewController();
  ViewController(ViewController&&) noexcept;             ///< moves the task and its features
  ViewController& operator=(ViewController&&) noexcept;  ///< moves the task and its features
  ViewController(const ViewController&) = delete;
  ViewController& operator=(const ViewController&) = delete;

  /**
   * \param tf        the view to reach (world frame) [m].
   * \param centroid  object centroid C (world frame) [m].
   * \param r_sphere  sphere radius [m].
   * \param wMc       current camera pose.
   * \param dt        time since the previous call [s] (for the target filter).
   * \return the camera twist (v, w) in the camera frame [m/s, rad/s].
   */
  [[nodiscard]] vpColVector update(const Eigen::Vector3d& tf, const Eigen::Vector3d& centroid,
                                   double r_sphere, const vpHomogeneousMatrix& wMc, double dt);

  /// \brief Forgets the filtered target (a new episode, a re-acquired object).
  void reset() { filtered_.reset(); }
  /// \brief The settings it was constructed with.
  [[nodiscard]] const ControllerSettings& settings() const { return settings_; }
  /// \brief The error norm of the last update (feature or pose error).
  [[nodiscard]] double last_error() const { return last_error_; }

 private:
  [[nodiscard]] double lambda(double error_norm) const;

  struct Task;  // the vpServo task and the features it points to

  ControllerSettings settings_;
  std::unique_ptr<Task> task_;
  std::optional<Eigen::Vector3d> filtered_;
  double last_error_ = 0.0;
};

/// \brief Scales a twist by one factor, the largest that keeps its linear part
/// within max_linear [m/s] and its angular part within max_angular [rad/s]:
/// the twist's direction is kept, so a task's rotation stays in step with its
/// translation (the sphere law's centring of C), only slower.
[[nodiscard]] vpColVector saturate(const vpColVector& v, double max_linear, double max_angular);

}  // namespace ofv::servo

/// \cond OFV_OLD_NAMES
// The names of ofv 0.1, kept for one release: use ofv::servo::.
namespace ofv {
using ControllerSettings [[deprecated("use ofv::servo::ControllerSettings")]] = servo::ControllerSettings;
using ViewController [[deprecated("use ofv::servo::ViewController")]] = servo::ViewController;
using servo::validate;
}  // namespace ofv
/// \endcond
