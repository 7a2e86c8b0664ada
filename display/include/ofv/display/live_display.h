/**
 * \file live_display.h
 * \brief Live ViSP windows on the closed loop (`--display` of `ofv simulate`,
 *        `ofv run` and the servo tutorials): the camera image with the
 *        object's supervoxels, the occluders and their tracks, the centroid
 *        and the sphere feature's current and desired values; the Fig.
 *        6-style scene view (ofv::scene_picture); vpPlot curves of the true
 *        visible fraction (simulation), the camera velocity and the feature
 *        error. A left click (or space, p) pauses and resumes; a right click
 *        (or q, Escape) ends the run.
 *
 * The windows are vpDisplayX, or vpDisplayOpenCV where ViSP has no X11.
 * The display only reads what the loop did: a run is the same with and
 * without it.
 *
 * \code
 * ofv::LiveDisplay display({});  // throws ofv::DisplayUnavailable without a display
 * const auto outcome = ofv::run_episode(setup, [&](const auto& rec, const auto& d) {
 *   if (!display.observe(rec, d)) throw MyQuit{};  // right click or q: the user ends the episode
 * });
 * \endcode
 */
#pragma once

#include "ofv/loop/episode.h"
#include "ofv/rgbd_frame.h"
#include "ofv/servo/robot_loop.h"
#include "ofv/servo/view_loop.h"

#include <visp3/core/vpColVector.h>
#include <visp3/core/vpImage.h>
#include <visp3/core/vpRGBa.h>
#include <Eigen/Geometry>

#include <functional>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

namespace ofv {

/// \brief No window can be opened: DISPLAY is not set, the X connection
///        fails, or this ViSP has no display. The message is one line.
class DisplayUnavailable : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/**
 * \brief The live display's state machine: what a click or a key does.
 *
 * Running ⇄ Paused on a left or middle click, space or p; Quit on a right
 * click, q or Escape, from either state. Quit is final. Without pause (a run
 * whose robot a pause could not hold) the pause events change nothing.
 */
class DisplayControl {
 public:
  /// \param pausable false: the pause events change nothing (a run a pause could not hold).
  explicit DisplayControl(bool pausable = true) : pausable_(pausable) {}
  /// \brief Where the run is: going, paused by the user, or ended by the user (final).
  enum class State { Running, Paused, Quit };
  /// \brief What the user did in a window.
  enum class Event {
    LeftClick,
    MiddleClick,
    RightClick,
    PauseKey,  ///< space or p
    QuitKey,   ///< q or Escape
  };
  /// \brief Applies an event; returns the new state.
  State handle(Event event);
  /// \brief The current state (Running at first).
  [[nodiscard]] State state() const { return state_; }
  /// \brief The event a key name (as vpDisplay::getKeyboardEvent gives it) stands for, if any.
  [[nodiscard]] static std::optional<Event> key_event(const std::string& key);

 private:
  bool pausable_ = true;
  State state_ = State::Running;
};

/// \brief How the live display looks and paces.
struct LiveDisplayOptions {
  std::string title = "ofv";  ///< prefix of the window titles
  double r_sphere = 0.5;      ///< the sphere radius R of the feature and the scene view [m]
  /// Plot the true visible fraction (there is a ground truth: simulation).
  bool ground_truth = false;
  /// Wall-clock frames per second at most (the scenario's rate × a speed
  /// factor); 0: as fast as the loop runs.
  double pace_rate = 0.0;
  /// A click pauses. false where a pause cannot hold the robot: the loop
  /// runs inside a library call whose robot the caller cannot reach (the
  /// threaded arm of ofv::rehearse or of a real-time episode keeps its last
  /// velocity while its observer waits).
  bool pause = true;
  bool scene = true;  ///< open the scene view window
  bool plot = true;   ///< open the vpPlot window
};

/// \brief What one frame of the display shows (world frame, metres).
struct DisplayInput {
  double time = 0.0;                                      ///< [s]
  Eigen::Isometry3d wMc = Eigen::Isometry3d::Identity();  ///< the camera when the frame was taken
  /// The camera image; nullptr: a grey image of `intrinsics` (a loop without a sensor).
  const RgbdFrame* frame = nullptr;
  CameraIntrinsics intrinsics;           ///< used when `frame` is nullptr
  const Observation* observation = nullptr;  ///< supervoxels and occluders seen and presumed (nullptr: none)
  const servo::LoopStep* step = nullptr;  ///< what ofv::servo::ViewLoop did (nullptr: a loop of the caller's own)
  /// The object's centroid when the step has no estimate (simulation: the true one).
  std::optional<Eigen::Vector3d> centroid;
  std::optional<Eigen::Vector3d> target;   ///< the view driven to, when there is no step
  std::optional<double> visible_fraction;  ///< the true visible fraction (simulation only)
  std::optional<servo::StepStatus> status;        ///< default: the step's (none without a step)
  /// The camera twist sent (v, w) [m/s, rad/s]; default: the step's velocity.
  std::optional<vpColVector> velocity;
};

/**
 * \brief The live windows. Construct once per run; call show() (or
 *        observe()) every frame from the loop's observer.
 */
class LiveDisplay {
 public:
  /// \throws DisplayUnavailable (one line) when no window can be opened.
  explicit LiveDisplay(const LiveDisplayOptions& options);
  ~LiveDisplay();
  LiveDisplay(const LiveDisplay&) = delete;
  LiveDisplay& operator=(const LiveDisplay&) = delete;

  /**
   * \brief Draws the frame, updates the plots, handles clicks and keys;
   *        while paused, waits here (calling the pause hook first).
   * \return false once the user asked to end the run (then the caller
   *         stops: `ofv run` through its stop flag, `ofv simulate` ends
   *         the episode early).
   */
  bool show(const DisplayInput& input);
  /// \brief show() for a step of ofv::run_episode (true visible fraction and centroid from the
  /// simulator).
  bool observe(const StepRecord& record, const StepDetail& detail);
  /// \brief show() for a frame of ofv::servo::run_on_robot or ofv::rehearse (no ground truth).
  bool observe(const servo::RobotLoopFrame& frame);

  /// \brief Called when a pause starts, before waiting (e.g. send the robot a zero velocity).
  void set_pause_hook(std::function<void()> hook);
  /// \brief Applies an event as a click or a key would (tests, other front ends).
  DisplayControl::State handle(DisplayControl::Event event);
  /// \brief The state of its DisplayControl: running, paused or quit.
  [[nodiscard]] DisplayControl::State state() const;
  /// \brief True once the user asked to end the run (right click, q or Escape).
  [[nodiscard]] bool quit_requested() const { return state() == DisplayControl::State::Quit; }

  /// \brief The camera window's pixels as shown (vpDisplay::getImage).
  void grab_camera(vpImage<vpRGBa>& image) const;
  /// \brief The scene window's pixels as shown; empty without a scene window.
  void grab_scene(vpImage<vpRGBa>& image) const;
  /// \brief The curves window's pixels as shown; empty without it.
  void grab_plot(vpImage<vpRGBa>& image) const;
  /// \brief Where the last frame's centroid projected in the camera image [px], if in front.
  [[nodiscard]] std::optional<Eigen::Vector2d> last_centroid_pixel() const;
  /// \brief The sphere feature's error s - s* of the last frame: (x, y, rho - R, f) (empty when
  /// undefined).
  [[nodiscard]] vpColVector last_feature_error() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace ofv
