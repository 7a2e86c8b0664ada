/**
 * \file robot.h
 * \brief Eye-in-hand robots as the closed loop sees them: take a camera
 *        twist for one frame period, report the new camera pose.
 *
 * - FreeFlyingCamera: ViSP's vpSimulatorCamera (the twist integrated
 *   exactly over dt), deterministic.
 * - KinematicArm on ViSP's kinematic models of the Viper850 (6-axis arm) and
 *   the Afma6 (gantry): q̇ from v by damped least squares on cVe eJe,
 *   integrated over dt, the step shortened so that no joint exceeds 2.5 rad/s
 *   (m/s) or passes its limit; faster than real time and deterministic.
 * - ThreadedArm: ViSP's threaded vpSimulatorViper850/Afma6, in wall-clock
 *   time (real-time demos).
 * - VispRobot: any ViSP vpRobot driver (real or threaded simulator) through
 *   setVelocity(CAMERA_FRAME) and its measured pose.
 *
 * The world frame W is the scenario's: an arm's base is placed so that its
 * start configuration puts the camera at the requested start pose.
 */
#pragma once

#include <visp3/core/vpColVector.h>
#include <visp3/core/vpHomogeneousMatrix.h>
#include <visp3/core/vpPoseVector.h>
#include <visp3/robot/vpRobot.h>
#include <visp3/robot/vpSimulatorCamera.h>

#include <functional>
#include <memory>
#include <string>

namespace ofv::servo {

/// \brief The simulated robots ofv can step (real drivers come through VispRobot).
enum class RobotKind {
  Camera,    ///< a free-flying camera (vpSimulatorCamera)
  Viper850,  ///< ViSP's Viper850 6-axis arm
  Afma6,     ///< ViSP's Afma6 gantry
};

/// \brief The robot's word in settings and files: camera, viper850, afma6.
[[nodiscard]] const char* to_string(RobotKind kind);
/// \brief The kind named `word`. \throws std::invalid_argument naming the setting `robot` and the word.
[[nodiscard]] RobotKind parse_robot_kind(const std::string& word);

/// \brief Result of one robot step.
struct RobotStep {
  vpHomogeneousMatrix wMc;  ///< camera pose after the step
  bool limited = false;     ///< a joint limit (or the workspace) stopped part of the motion
};

/// \brief A robot carrying the camera.
class CameraRobot {
 public:
  virtual ~CameraRobot() = default;
  /// \brief Current camera pose in the world.
  [[nodiscard]] virtual vpHomogeneousMatrix wMc() const = 0;
  /// \brief Applies the camera twist v (camera frame, [m/s, rad/s]) for dt seconds.
  virtual RobotStep step(const vpColVector& v, double dt) = 0;
  /// \brief The robot's name in messages and records (`camera`, `viper850`, ...).
  [[nodiscard]] virtual std::string name() const = 0;
};

/// \brief A free-flying camera: vpSimulatorCamera, stepped by dt with no speed
///        limit of its own (the controller and the safety filter bound it).
class FreeFlyingCamera : public CameraRobot {
 public:
  /// \param wMc the camera's start pose.
  explicit FreeFlyingCamera(const vpHomogeneousMatrix& wMc);
  [[nodiscard]] vpHomogeneousMatrix wMc() const override { return camera_.getPosition(); }
  RobotStep step(const vpColVector& v, double dt) override;
  [[nodiscard]] std::string name() const override { return "camera"; }

 private:
  vpSimulatorCamera camera_;
};

/// \brief A ViSP arm model (vpViper850 or vpAfma6) stepped on its kinematics.
class KinematicArm : public CameraRobot {
 public:
  /// \brief Which of ViSP's arm models.
  enum class Model { Viper850, Afma6 };
  /// \brief The arm in start_joints(model).
  /// \param model     the arm.
  /// \param wMc_start camera start pose; the base is placed to match it.
  KinematicArm(Model model, const vpHomogeneousMatrix& wMc_start);
  /// \brief The start configuration: away from singularities and joint limits, camera forward.
  [[nodiscard]] static vpColVector start_joints(Model model);
  ~KinematicArm() override;
  [[nodiscard]] vpHomogeneousMatrix wMc() const override;
  RobotStep step(const vpColVector& v, double dt) override;
  [[nodiscard]] std::string name() const override;
  /// \brief The joint positions [rad or m].
  [[nodiscard]] const vpColVector& joints() const { return q_; }
  /// \brief The model's lower joint limits [rad or m].
  [[nodiscard]] vpColVector joint_min() const;
  /// \brief The model's upper joint limits [rad or m].
  [[nodiscard]] vpColVector joint_max() const;
  /// \brief Sets the joints (clamped to the limits); for tests and start poses.
  void set_joints(const vpColVector& q);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  vpColVector q_;
  vpHomogeneousMatrix wMf_;  // base in the world
};

/**
 * \brief Any ViSP robot (a real driver such as vpRobotViper850, vpRobotAfma6,
 *        vpRobotFranka, vpRobotUniversalRobots, or a threaded simulator),
 *        commanded in the camera frame. step() sends the velocity with
 *        setVelocity(CAMERA_FRAME) (or `command`) and waits until one period after the
 *        previous step began (vpTime::wait), so that the loop keeps the frame
 *        rate whatever its compute time; the camera pose is read back with
 *        getPosition(REFERENCE_FRAME, vpPoseVector&) (θu: the vpColVector
 *        overload gives Rxyz angles on ViSP's arms). `fMw` places the world.
 */
class VispRobot : public CameraRobot {
 public:
  /// \brief Reads the camera pose in the robot's reference frame, fMc.
  using PoseReader = std::function<vpHomogeneousMatrix()>;
  /// \brief Sends a camera twist to the robot (ThreadedArm slows it near joint limits).
  using Command = std::function<void(const vpColVector& v)>;
  /// \brief `Driver`: any vpRobot with getPosition(vpRobot::REFERENCE_FRAME, vpPoseVector&).
  /// \param robot   the driver; it must outlive this object. Set to velocity control.
  /// \param fMw     the world frame in the robot's reference frame.
  /// \param name    the robot's name().
  /// \param command sends the twist; empty: setVelocity(CAMERA_FRAME, v).
  template <class Driver>
  VispRobot(Driver& robot, const vpHomogeneousMatrix& fMw, std::string name, Command command = {})
      : VispRobot(static_cast<vpRobot&>(robot), PoseReader([&robot] {
                    vpPoseVector p;
                    robot.getPosition(vpRobot::REFERENCE_FRAME, p);
                    return vpHomogeneousMatrix(p);
                  }),
                  fMw, std::move(name), std::move(command)) {}
  /// \brief As the template constructor, with the camera pose read by `fMc`.
  VispRobot(vpRobot& robot, PoseReader fMc, const vpHomogeneousMatrix& fMw, std::string name, Command command = {});
  [[nodiscard]] vpHomogeneousMatrix wMc() const override;
  RobotStep step(const vpColVector& v, double dt) override;
  [[nodiscard]] std::string name() const override { return name_; }
  /// \brief Zero velocity now (Ctrl-C, lost object).
  void stop();

 private:
  vpRobot& robot_;
  PoseReader fMc_;
  Command command_;
  vpHomogeneousMatrix wMf_;
  std::string name_;
  double next_ms_ = -1.0;  // when the current period ends (vpTime::measureTimeMs)
};

/**
 * \brief ViSP's threaded simulators, vpSimulatorViper850 and vpSimulatorAfma6
 *        (headless), through VispRobot: they integrate in wall-clock time, so
 *        an episode runs in real time and is not exactly repeatable. For
 *        demos; KinematicArm is the deterministic twin. The arm starts in
 *        KinematicArm::start_joints(), its base placed so that the camera is
 *        at `wMc_start`. The twist is slowed (its direction kept) so that no
 *        joint, its velocity estimated by damped least squares on the
 *        simulator's Jacobian, comes within `kJointLimitMargin` of its
 *        limit: ViSP 3.5's simulators turn every joint into NaN when a joint
 *        that stands on its limit is given no velocity of its own
 *        (vpSimulatorViper850::updateArticularPosition divides by it).
 */
class ThreadedArm : public CameraRobot {
 public:
  /// \throws std::runtime_error when this ViSP has no threaded simulators.
  ThreadedArm(KinematicArm::Model model, const vpHomogeneousMatrix& wMc_start);
  ~ThreadedArm() override;  ///< stops the arm
  [[nodiscard]] vpHomogeneousMatrix wMc() const override;
  RobotStep step(const vpColVector& v, double dt) override;
  [[nodiscard]] std::string name() const override;
  /// \brief The simulator's joints now, and its limits (its own, narrower than KinematicArm's on the Viper850).
  [[nodiscard]] vpColVector joints() const;
  [[nodiscard]] vpColVector joint_min() const;  ///< the simulator's lower joint limits [rad or m]
  [[nodiscard]] vpColVector joint_max() const;  ///< the simulator's upper joint limits [rad or m]
  /// \brief How close [rad or m] a joint may come to its limit.
  static constexpr double kJointLimitMargin = 0.02;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/**
 * \brief A FreeFlyingCamera, or a KinematicArm (ThreadedArm when `real_time`)
 *        whose camera starts at `wMc_start`.
 * \throws std::invalid_argument for the camera in real time.
 */
[[nodiscard]] std::unique_ptr<CameraRobot> make_robot(RobotKind kind, const vpHomogeneousMatrix& wMc_start,
                                                      bool real_time = false);

}  // namespace ofv::servo

/// \cond OFV_OLD_NAMES
// The names of ofv 0.1, kept for one release: use ofv::servo::.
namespace ofv {
using CameraRobot [[deprecated("use ofv::servo::CameraRobot")]] = servo::CameraRobot;
using FreeFlyingCamera [[deprecated("use ofv::servo::FreeFlyingCamera")]] = servo::FreeFlyingCamera;
using KinematicArm [[deprecated("use ofv::servo::KinematicArm")]] = servo::KinematicArm;
using ThreadedArm [[deprecated("use ofv::servo::ThreadedArm")]] = servo::ThreadedArm;
using VispRobot [[deprecated("use ofv::servo::VispRobot")]] = servo::VispRobot;
using RobotKind [[deprecated("use ofv::servo::RobotKind")]] = servo::RobotKind;
using RobotStep [[deprecated("use ofv::servo::RobotStep")]] = servo::RobotStep;
using servo::make_robot;
using servo::parse_robot_kind;
using servo::to_string;
}  // namespace ofv
/// \endcond
