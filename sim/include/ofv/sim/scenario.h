/**
 * \file scenario.h
 * \brief Simulated scenarios: a YAML description (docs/scenarios.md) of the
 *        sensor, the camera's start, the target object and its motion or
 *        deformation, the element holding it, moving occluders, the table,
 *        and the estimator, robot and controller settings.
 *
 * World frame W: metres; bodies move along timed waypoints.
 */
#pragma once

#include "ofv/estimator.h"
#include "ofv/rgbd_frame.h"
#include "ofv/sim/mesh.h"

#include <Eigen/Geometry>

#include <map>
#include <string>
#include <vector>

namespace ofv::sim {

/// \brief A timed pose: position [m] and roll-pitch-yaw [deg] (fixed axes x, y, z).
struct Waypoint {
  double t = 0.0;  ///< [s]
  Eigen::Vector3d position = Eigen::Vector3d::Zero();  ///< world frame [m]
  Eigen::Vector3d rpy_deg = Eigen::Vector3d::Zero();   ///< roll, pitch, yaw [deg] (rpy_deg_to_matrix())
};

/// \brief Piecewise motion through waypoints: linear in position, slerp in
///        rotation; held still before the first and after the last.
struct Motion {
  std::vector<Waypoint> waypoints;  ///< sorted by t, at least one
  /// \brief Pose of the body in the world at time t [s].
  [[nodiscard]] Eigen::Isometry3d at(double t) const;
};

/// \brief Rotation from roll, pitch, yaw in degrees: Rz(yaw) Ry(pitch) Rx(roll).
[[nodiscard]] Eigen::Matrix3d rpy_deg_to_matrix(const Eigen::Vector3d& rpy_deg);

/// \brief What a body is to the perception and the metrics.
enum class Role { Object, Interacting, Occluder, Background };

/// \brief A rigid or deformable body of the scene.
struct Body {
  std::string name;                  ///< label in outputs (object, holder, occluderN, table by default)
  Role role = Role::Occluder;        ///< object, holder (interacting), occluder or table (background)
  std::string shape;                 ///< box, sphere, capsule, sheet, cloth, mesh, plane
  TriangleMesh mesh;                 ///< at rest, body frame
  std::string mesh_file;             ///< shape mesh: the file it was read from
  Eigen::Vector3f colour{0.5f, 0.5f, 0.5f};  ///< RGB in [0, 1]
  Motion motion;                     ///< its pose over time (a fixed pose: one waypoint)
  /// Cloth only: travelling wave and bend along body x (see deform_sheet).
  double wave_amplitude = 0.0, wave_length = 0.2, wave_frequency = 0.0, bend = 0.0;
  /** \var wave_length
   *  \brief Cloth only: wavelength of the travelling wave [m].
   *  \var wave_frequency
   *  \brief Cloth only: frequency of the travelling wave [Hz].
   *  \var bend
   *  \brief Cloth only: bend along body x, dz = bend x^2 [1/m].
   */
  /// Probability that a pixel showing this body has no depth when the
  /// sensor's noise is on: a dark or shiny surface [0, 1].
  double dropout = 0.0;
  /// \brief True for a cloth, whose mesh world_mesh() deforms with time.
  [[nodiscard]] bool deformable() const { return shape == "cloth"; }
  /// \brief The body's mesh in the world frame at time t.
  [[nodiscard]] TriangleMesh world_mesh(double t) const;
};

/// \brief Depth noise of the simulated sensor.
struct NoiseModel {
  bool enabled = true;          ///< noise and dropouts on (the bodies' `dropout` too)
  double depth_sigma = 0.001;   ///< Gaussian sigma at 1 m; grows with depth^2 [m]
  double grazing_deg = 78.0;    ///< pixels seen more obliquely than this are missing [deg]
  double edge_jump = 0.03;      ///< depth step that makes a pixel an edge [m]
  double edge_dropout = 0.5;    ///< probability that an edge pixel is missing
};

/// \brief The simulated RGB-D sensor.
struct SensorSettings {
  CameraIntrinsics intrinsics;  ///< default: the `fast-320` preset
  double min_depth = 0.1;       ///< [m]
  double max_depth = 3.0;       ///< [m]
  NoiseModel noise;             ///< depth noise and dropouts
};

/// \brief Intrinsics presets: `d435-640` (640x480, D435-like) and `fast-320` (320x240).
[[nodiscard]] CameraIntrinsics intrinsics_preset(const std::string& name);

/// \brief How much the occluders' motion changes from one seed to the next.
struct Variation {
  double time = 0.0;      ///< each occluder's motion is delayed by a draw in [-time, time] [s]
  double position = 0.0;  ///< and moved by a draw in the ball of this radius [m]
};

/// \brief A whole scenario.
struct Scenario {
  std::string name;       ///< file stem
  std::string path;       ///< file it came from
  double duration = 4.0;  ///< [s]
  double rate = 30.0;     ///< sensor rate [Hz]
  unsigned seed = 1;      ///< sensor noise seed (frame k uses seed and k)
  Variation variation;    ///< what with_seed() draws for seeds other than 0
  SensorSettings sensor;  ///< the simulated RGB-D sensor
  Eigen::Isometry3d wMc_start = Eigen::Isometry3d::Identity();  ///< camera start pose
  std::vector<Body> bodies;  ///< the object first
  EstimatorParams estimator;  ///< the file's `estimator` settings (preset and overrides)
  std::string robot = "camera";  ///< camera, viper850, afma6
  std::map<std::string, std::string> controller;  ///< law, gain, ... (read by the servo layer)
  /// \brief The sphere's radius the scenario asks for, else the estimator's default [m].
  double r_sphere() const { return estimator.r_sphere.value_or(EstimatorSettings{}.r_sphere); }
  /// \brief The seed resolution the scenario asks for, else the estimator's default [m].
  double r_seed() const { return estimator.r_seed.value_or(EstimatorSettings{}.r_seed); }
};

/// \brief Parses a scenario from YAML text; `source` names it in errors.
/// \throws std::invalid_argument naming the file, the key and the value.
[[nodiscard]] Scenario scenario_from_yaml(const std::string& text, const std::string& source);

/**
 * \brief The scenario's k-th random world: the sensor noise seed becomes
 *        seed + k and, for k > 0, every occluder's motion is shifted in time
 *        and space by draws within `variation` (from seed and k only, so the
 *        same for every setting). k = 0 is the scenario as written.
 */
[[nodiscard]] Scenario with_seed(const Scenario& scenario, unsigned k);

/// \brief Loads a scenario file, or a built-in scenario by name (e.g. `dvd-one-hand`).
[[nodiscard]] Scenario load_scenario(const std::string& path_or_name);

/**
 * \brief Folder of the built-in scenarios, the first of: `$OFV_DATA_DIR/scenarios`
 *        when that variable is set (`OFV_SCENARIO_DIR`, the folder itself, too);
 *        the source tree's `sim/scenarios` when libofv_sim runs from its build
 *        folder; `share/ofv/scenarios` relative to the loaded libofv_sim (so a
 *        moved install prefix works); the configured install prefix's.
 */
[[nodiscard]] std::string builtin_scenario_dir();
/// \brief Names of the built-in scenarios, sorted.
[[nodiscard]] std::vector<std::string> builtin_scenarios();
/// \brief The scenario `ofv simulate` runs when given none.
constexpr const char* kDefaultScenario = "dvd-one-hand";

}  // namespace ofv::sim
