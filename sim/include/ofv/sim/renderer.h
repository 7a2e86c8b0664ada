/**
 * \file renderer.h
 * \brief Ray-cast RGB-D rendering (Embree) of a scenario at a time and a
 *        camera pose, with per-pixel labels, and the ground truth the
 *        closed-loop metrics stand on.
 *
 * Camera convention (ViSP's): X right, Y down, Z along the optical axis;
 * `wMc` maps camera to world coordinates. Depth is Z in metres.
 */
#pragma once

#include "ofv/estimator.h"
#include "ofv/rgbd_frame.h"
#include "ofv/sim/scenario.h"

#include <cstdint>
#include <memory>
#include <vector>

namespace ofv::sim {

/// \brief Label image values.
enum Label : std::uint16_t {
  kLabelNone = kPixelNone,                ///< nothing hit (beyond the depth range)
  kLabelObject = kPixelObject,
  kLabelInteracting = kPixelInteracting,
  kLabelBackground = kPixelSupport,       ///< the table
  kLabelOccluder0 = kPixelOccluder0,      ///< occluder k is kLabelOccluder0 + k
};

/// \brief A rendered frame; its ground truth is `frame.labels` and `frame.object_centroid`.
struct RenderedFrame {
  RgbdFrame frame;  ///< depth, colour and labels at the camera's pose, with the object's centroid
};

/// \brief Ground truth of the object at one time and camera pose.
struct ObjectTruth {
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();  ///< area-weighted surface centroid [m]
  /// Of the object's surface samples that face the camera, the fraction it sees:
  /// in its image and depth range, with nothing in between [0, 1].
  double visible_fraction = 0.0;
  int occluders_in_sphere = 0;    ///< occluders with a vertex within r_sphere of the centroid
};

/// \brief The occluders a rendered frame shows (distinct occluder labels):
///        with full perception nothing earlier can warn the loop of one.
[[nodiscard]] int occluders_seen(const std::vector<std::uint16_t>& labels);

/**
 * \brief Renders one scenario. set_time() rebuilds the moving and deforming
 *        geometry; every other call is const and thread-compatible.
 */
class Renderer {
 public:
  /// \param scenario        the world to render; the renderer keeps a copy.
  /// \param surface_samples object surface samples for the ground truth.
  explicit Renderer(const Scenario& scenario, int surface_samples = 4000);
  ~Renderer();
  Renderer(const Renderer&) = delete;
  Renderer& operator=(const Renderer&) = delete;

  /// \brief Places every body at time t [s].
  void set_time(double t);
  /// \brief The time of the last set_time() [s]; -1 before the first.
  [[nodiscard]] double time() const { return time_; }

  /**
   * \brief Renders depth, colour and labels from `wMc` with the scenario's
   *        sensor. Noise is drawn from a generator seeded with the
   *        scenario's seed and `frame_index`, so a frame is reproducible.
   */
  [[nodiscard]] RenderedFrame render(const Eigen::Isometry3d& wMc, long frame_index) const;
  /// \brief The same with other intrinsics and noise switched on or off.
  [[nodiscard]] RenderedFrame render(const Eigen::Isometry3d& wMc, long frame_index,
                                     const CameraIntrinsics& intrinsics, bool noise) const;
  /// \brief The same into `out`, reusing its images' memory: a loop that
  ///        renders frame after frame into one RenderedFrame allocates (and
  ///        has the system clear) no memory after its first frame.
  void render(const Eigen::Isometry3d& wMc, long frame_index, const CameraIntrinsics& intrinsics, bool noise,
              RenderedFrame& out) const;

  /// \brief Object ground truth seen from a camera at `wMc` (r_sphere for the occluder count).
  [[nodiscard]] ObjectTruth truth(const Eigen::Isometry3d& wMc, double r_sphere) const;

  /**
   * \brief truth()'s visible fraction from each camera pose at the current
   *        time, the poses shared out among threads (oneTBB): what a planner
   *        that scores many views of one instant asks for. Rays are cast
   *        only where the answer is not known without them: none when a body
   *        that is its own bounding box (a table) lies across every line of
   *        sight, none when the object is rigid and convex and no other
   *        body's box can lie on a line of sight (the same values).
   * \throws std::invalid_argument when a pose is not finite.
   */
  [[nodiscard]] std::vector<double> visible_fractions(const std::vector<Eigen::Isometry3d>& poses) const;
  /**
   * \brief The same where only fractions of at least `at_least[k]` matter
   *        for pose k: its rays stop once fewer than that can be seen. Then
   *        its entry is the fraction that could still be seen, an upper
   *        bound below `at_least[k]`, and `exact[k]` is 0; otherwise the
   *        entry is visible_fractions()' and `exact[k]` is 1. The samples go
   *        in blocks spread over the object's surface; with `missed`, pose
   *        k's samples set in `(*missed)[k]` (a bitset over the object's
   *        samples: those an earlier call found not seen from a view near
   *        this one) go first, and `(*missed)[k]` becomes those this call
   *        found not seen (left as it was where the threshold is 0 or
   *        less). A threshold of 0 or less never stops the rays.
   * \throws std::invalid_argument when a pose is not finite or the sizes differ.
   */
  [[nodiscard]] std::vector<double> visible_fractions(const std::vector<Eigen::Isometry3d>& poses,
                                                      const std::vector<double>& at_least, std::vector<char>& exact,
                                                      std::vector<std::vector<std::uint64_t>>* missed = nullptr) const;

  /// \brief The object's area-weighted surface centroid (truth()'s) at the current time [m].
  [[nodiscard]] Eigen::Vector3d object_centroid() const;
  /// \brief The object's surface samples (those of truth()) at the current time [m].
  [[nodiscard]] std::vector<Eigen::Vector3d> object_surface() const;

  /**
   * \brief What perfect perception would give the estimator: object
   *        supervoxels (the camera-facing surface samples grouped in an
   *        r_seed grid, centroid and normal per cell, normals towards the
   *        camera side), and as occluders the r_seed-grid cells of the
   *        camera-facing surfaces of the occluders and the table inside the
   *        sphere and outside the object's augmented OBB (PCA box grown by
   *        `obb_margin`), as the paper classifies them.
   */
  [[nodiscard]] ViewProblem ground_truth_problem(const Eigen::Isometry3d& wMc, double r_seed,
                                                 double r_sphere, double obb_margin = 0.03) const;
  /// \brief ground_truth_problem() without occluders: the object's
  ///        supervoxels and the camera only (what the metrics' angular error
  ///        stands on, at a fraction of the cost).
  [[nodiscard]] ViewProblem ground_truth_object(const Eigen::Isometry3d& wMc, double r_seed) const;

  /// \brief The scenario it renders (its copy).
  [[nodiscard]] const Scenario& scenario() const { return scenario_; }

 private:
  struct Impl;
  Scenario scenario_;
  double time_ = -1.0;
  std::unique_ptr<Impl> impl_;
};

}  // namespace ofv::sim
