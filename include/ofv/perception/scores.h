/**
 * \file scores.h
 * \brief How good the front end's output is, frame by frame, against a
 *        frame's ground-truth labels (the simulator's, or those of ofv's own
 *        recordings): object and occluder precision and recall by voxel,
 *        centroid error, error of the remembered hidden part.
 *
 * Every measure counts voxels of the front end's own grid (edge
 * SupervoxelSettings::voxel_resolution, world-aligned cells), so a score is
 * about what this sensor shows at the front end's resolution:
 *
 * - The true label of a voxel (VoxelLabels) is the label most of the
 *   frame's pixels in it show (every `pixel_stride`-th pixel with depth, as
 *   the front end samples them). A point of the front end is scored by the
 *   cell it lies in, or the nearest occupied cell around it (PCL's voxels are
 *   means of points and may fall just outside theirs).
 * - Object precision: of the voxels the front end calls object in this
 *   frame, the fraction whose cell is object. Object recall: of the object
 *   cells the frame shows, the fraction with a voxel the front end calls
 *   object within one voxel edge of the cell's points (PCL re-grids the
 *   voxels: they are fewer than the cells and off their centres). Lost:
 *   recall 0, no precision.
 * - Occluder precision: of the voxels the front end calls occluder, the
 *   fraction whose cell is an occluding body; voxels of the support (the
 *   table, an occluder by the paper's rule when support_plane_occludes) are
 *   left out, so the object's, its holder's or empty cells counted as
 *   occluders are the errors. Occluder recall: of the cells of occluding
 *   bodies within r_sphere of the true centroid, the fraction with a voxel
 *   the front end calls occluder within one voxel edge.
 * - Centroid error: |C - true centroid| [m]; the true centroid is the whole
 *   surface's, so an object seen from one side keeps a bias of about half
 *   its thickness.
 * - Hidden error: mean distance [m] from the remembered object voxels not
 *   seen in this frame (PerceptionResult::hidden) to the object's true
 *   surface at this time, given as samples: the nearest sample's distance,
 *   which reads up to about half the samples' spacing for a point on the
 *   surface.
 *
 * A measure whose denominator is empty is std::nullopt (no occluder in the
 * sphere: no occluder recall), and so is one whose truth is not known.
 */
#pragma once

#include "ofv/perception/perception.h"
#include "ofv/rgbd_frame.h"

#include <Eigen/Core>

#include <cstdint>
#include <memory>
#include <optional>
#include <vector>

namespace ofv::perception {

/**
 * \brief A labelled frame's pixels on a world voxel grid: the label most of
 *        each voxel's pixels show.
 */
class VoxelLabels {
 public:
  /// \brief One occupied voxel.
  struct Cell {
    Eigen::Vector3f mean = Eigen::Vector3f::Zero();  ///< mean of its pixels' points [m]
    std::uint16_t label = kPixelNone;                ///< the label most of them show
  };

  /// \brief The voxel grid of `frame`'s labelled pixels.
  /// \param frame  a frame with labels
  /// \param voxel  edge of the cells [m] (> 0)
  /// \param stride every stride-th pixel in u and v (>= 1), as CloudSettings::pixel_stride
  /// \param max_depth pixels farther along the optical axis are left out [m]
  /// \throws std::invalid_argument when the frame has no labels or the
  ///         arguments are out of range (and as check_frame()).
  VoxelLabels(const RgbdFrame& frame, double voxel, int stride, double max_depth);

  /// \brief Index of the cell holding p, else of the occupied cell among its
  ///        26 neighbours whose mean is nearest p; -1 when none.
  [[nodiscard]] int find(const Eigen::Vector3f& p) const;
  /// \brief The label of find(p); kPixelNone when there is no cell.
  [[nodiscard]] std::uint16_t label_at(const Eigen::Vector3f& p) const;

  /// \brief The occupied cells, indexed as find() returns them.
  [[nodiscard]] const std::vector<Cell>& cells() const { return cells_; }

 private:
  struct Index;  // the occupied cells' hash
  float inv_voxel_ = 1.0f;
  std::shared_ptr<const Index> index_;
  std::vector<Cell> cells_;
};

/// \brief What the scores compare against, besides the frame's labels.
struct PerceptionTruth {
  /// The object's true surface centroid [m]; without it no occluder recall
  /// (whose sphere it centres) and no centroid error.
  std::optional<Eigen::Vector3d> centroid;
  double r_sphere = 0.3;  ///< occluders are scored within this of the centroid [m]
  /// Samples of the object's true surface at the frame's time [m]; empty:
  /// no hidden error.
  std::vector<Eigen::Vector3d> surface;
};

/// \brief One frame's perception scores (see the file's description).
struct PerceptionScores {
  /// Of the voxels called object, the fraction whose cell is object.
  std::optional<double> object_precision;
  /// Of the object cells the frame shows, the fraction found as object.
  std::optional<double> object_recall;
  /// Of the voxels called occluder (the support's left out), the fraction
  /// whose cell is an occluding body.
  std::optional<double> occluder_precision;
  /// Of the occluding bodies' cells within r_sphere of the true centroid,
  /// the fraction found as occluder.
  std::optional<double> occluder_recall;
  std::optional<double> centroid_error;  ///< [m]
  std::optional<double> hidden_error;    ///< mean over the hidden voxels [m]
  std::size_t object_cells = 0;    ///< object cells the frame shows (recall's denominator)
  std::size_t occluder_cells = 0;  ///< occluding bodies' cells in the sphere (recall's denominator)
  std::size_t hidden_voxels = 0;   ///< remembered voxels scored by hidden_error
};

/**
 * \brief Scores the front end's result on a labelled frame.
 * \param frame    the frame the front end processed, with its labels.
 * \param result   what Perception::process() returned for it.
 * \param truth    the true centroid and surface, where known.
 * \param settings the front end's (voxel resolution, pixel stride, max depth).
 * \throws std::invalid_argument when the frame has no labels.
 */
[[nodiscard]] PerceptionScores score_perception(const RgbdFrame& frame, const PerceptionResult& result,
                                                const PerceptionTruth& truth, const PerceptionSettings& settings);

/**
 * \brief The object's surface a labelled frame shows [m²], in the unit of
 *        Observation::shown_area: its voxels (the cells most of whose pixels
 *        show the object) times a voxel's face. What a front end that
 *        classified every pixel right would report.
 * \param frame    a frame with labels
 * \param settings the front end's (voxel resolution, pixel stride, max depth).
 * \throws std::invalid_argument when the frame has no labels.
 */
[[nodiscard]] double labelled_shown_area(const RgbdFrame& frame, const PerceptionSettings& settings);

}  // namespace ofv::perception

/// \cond OFV_OLD_NAMES
// The names of ofv 0.1, kept for one release: use ofv::perception::.
namespace ofv {
using VoxelLabels [[deprecated("use ofv::perception::VoxelLabels")]] = perception::VoxelLabels;
using perception::labelled_shown_area;
using perception::score_perception;
using PerceptionScores [[deprecated("use ofv::perception::PerceptionScores")]] = perception::PerceptionScores;
using PerceptionTruth [[deprecated("use ofv::perception::PerceptionTruth")]] = perception::PerceptionTruth;
}  // namespace ofv
/// \endcond
