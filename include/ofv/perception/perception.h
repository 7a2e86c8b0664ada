/**
 * \file perception.h
 * \brief The perception front end of Cuiral-Zueco and López-Nicolás,
 *        "Dynamic Occlusion Handling for Real Time Object Perception",
 *        section II: supervoxels, the tracked object, its augmented OBB,
 *        interacting and occluding elements, and the estimator's ViewProblem.
 *
 * All positions are in the world frame W [m]. One Perception object follows
 * one object through a sequence of frames:
 *
 * \code
 * ofv::perception::Perception perception(ofv::perception::PerceptionSettings{});   // default start: see ObjectSelection
 * while (auto frame = source.next()) {
 *   const ofv::perception::PerceptionResult r = perception.process(*frame);
 *   if (r.status == ofv::perception::TrackingStatus::Lost) continue;
 *   const ofv::ViewEstimate e = ofv::estimate_view(r.problem, ofv::EstimatorSettings{});
 * }
 * \endcode
 *
 * Assumptions (paper, section II-C): frame 0 sees the whole object; the
 * object and the other elements move little between consecutive frames.
 */
#pragma once

#include "ofv/estimator.h"
#include "ofv/observation.h"
#include "ofv/perception/cloud.h"
#include "ofv/rgbd_frame.h"
#include "ofv/settings_table.h"

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

/**
 * \namespace ofv::perception
 * \brief The RGB-D front end (component `perception`): clouds, supervoxels,
 *        classes and tracking, its scores against labelled frames, its
 *        pictures and perceive(). The names of ofv 0.1 in `ofv`
 *        (`ofv::Perception`, ...) remain for one release as deprecated aliases.
 */
namespace ofv::perception {

/// \brief Settings of the supervoxel stage.
struct SupervoxelSettings {
  /// \brief Which implementation of VCCS supervoxels cuts the cloud.
  enum class Method {
    Ofv,  ///< ofv's own, on the voxel grid (src/perception/vccs.h): the default, 2-3x faster
    Pcl,  ///< pcl::SupervoxelClustering: the reference (docs/perception.md compares them)
  };
  Method method = Method::Ofv;  ///< the implementation
  double voxel_resolution = 0.008;  ///< voxel edge [m], >= 1e-4
  double seed_resolution = EstimatorSettings{}.r_seed;  ///< R_seed: spacing of supervoxel seeds [m] (paper: 0.02)
  double colour_importance = 0.2;   ///< weight of colour distance in the clustering
  double spatial_importance = 0.4;  ///< weight of spatial distance
  double normal_importance = 1.0;   ///< weight of normal difference
  /// alpha of paper eq. 1: two supervoxels are adjacent when their centroids
  /// lie within R_adj = alpha R_seed. The paper bounds it to [1, 1.5].
  double adjacency_alpha = 1.5;
};

/// \brief Settings of the object tracker.
struct TrackingSettings {
  /// Largest motion of an object surface point between consecutive frames
  /// [m] (paper assumption 2). A voxel of the new frame is near the object
  /// when it lies within this distance of the previous object's voxel cloud.
  double max_motion = 0.012;
  /// A supervoxel joins the object when at least this fraction of its voxels
  /// is near the previous object. Supervoxels respect colour and normal
  /// boundaries, so a hand touching the object forms its own supervoxels and
  /// stays out even though a few of its voxels touch the object.
  double min_near_fraction = 0.5;
  /// A voxel counts as near the object only if the object voxel it is near
  /// has a chromaticity similar to its own (R, G, B over their sum, so shading does not
  /// matter): Euclidean distance at most this. Keeps the table under the
  /// object and a touching hand of another colour out; <= 0 turns it off.
  /// A matched voxel is remembered with the chromaticity it matched, so a
  /// voxel mixing two colours cannot lead the next frame's match a step
  /// further towards a touching hand's. A supervoxel that joins the object
  /// gives up its voxels that match nothing remembered, were not revealed
  /// (grow_revealed) and are unlike, by more than twice this, the
  /// chromaticity its matched voxels remember: a hand's where VCCS merged it
  /// with the case's edge (as it gives up the support plane's,
  /// plane_distance).
  double max_chroma_distance = 0.06;
  /// The object is lost when fewer of its voxels than this fraction of what
  /// the view can show are found: the first frame's count, or fewer where
  /// the remembered object (seen or hidden) has fewer voxels facing the
  /// camera on pixels with depth (a face seen edge-on shows its edge). The
  /// last known state is kept for re-acquisition.
  double min_kept_fraction = 0.2;
  /// Object voxels not seen in a frame (behind something nearer the camera,
  /// out of the image, or on a pixel with no depth where the frame does not
  /// show the same voxel through other pixels: a sensor's shadow beside an
  /// occluder) are remembered for this many frames, so the occluded part is
  /// recognised when it reappears and stays part of the object [frames].
  int occlusion_memory_frames = 60;
  /// The remembered hidden voxels, grouped per cell of the seed resolution
  /// and per facing of their supervoxel's normal (as the seen part's
  /// supervoxels are), are vertices of the estimator's problem too, so the
  /// view keeps the whole object clear, not only the part still seen.
  /// false: only the supervoxels seen in the frame (the paper's reading).
  bool hidden_vertices = true;
  /// The remembered hidden voxels follow the object's rigid motion between
  /// consecutive frames, estimated from its visible part: a few Gauss-Newton
  /// (ICP) steps that align the frame's object voxels with the previous
  /// frame's, point-to-plane on the surface and, at the object's own outline
  /// (not where an occluder or the image border cuts it), along the
  /// outline's normal. So the part hidden behind a static occluder stays
  /// where the moving object is. Motion along a direction the visible part
  /// does not constrain (a plain face sliding in its plane with no outline
  /// seen) is taken as zero, and an estimate beyond max_motion or from too
  /// little of the object is dropped. false: hidden parts stay where they
  /// were last seen.
  bool follow_motion = true;
  /// Surface the object itself hid joins the object when it comes into
  /// view, even where no remembered voxel lies within max_motion (a camera
  /// moving round a folded cloth sees its far half appear from behind its
  /// near half): a voxel the previous frame could not see (in its image,
  /// behind a surface nearer its camera by more than max_motion) whose
  /// hiding surface was the object (a remembered voxel of the voxel's
  /// chromaticity) counts as the object's. A supervoxel joins when those
  /// and the near voxels make min_near_fraction of it, never one on the
  /// support plane nor one linked (voxels within R_adj) through surface of
  /// its colour to a surface of that colour seen before and not the
  /// object's (a distractor whose side the object hid could be either's);
  /// the counted voxels of one that does not yet are remembered, so that it
  /// joins once enough of it is. Surface the previous frame could not show
  /// otherwise — beyond its image (an object the first image cut) or facing
  /// its camera at less than 17 degrees from edge-on (the top of a box the
  /// camera rises over) — counts the same way when its supervoxel is linked
  /// through surface of its colour to the object, within R_adj of an object
  /// voxel of that colour with no empty space seen between the two (a body
  /// of the object's colour beside it is not its continuation). false: only what lies
  /// within max_motion of the remembered object (the paper's assumption 2).
  bool grow_revealed = true;
  /// Dominant plane (RANSAC on the first frame, at least a fifth of its
  /// points) inlier distance [m]. Supervoxels on that plane (centroid within
  /// this distance, normal within 60 degrees) are never object: the table
  /// the object rests on. Nor are voxels on the plane of the plane's colour
  /// (its mean chromaticity, within max_chroma_distance): an object
  /// supervoxel that straddles the object's foot and the plane gives them up
  /// (a piece of its own). With that and the colour's cut
  /// (max_chroma_distance), over 81 episodes (27 scenarios, 3 seeds) the
  /// frames with half the object in view and an object precision below 0.99
  /// went from 341 to 3 of 10 070 (docs/perception.md).
  double plane_distance = 0.01;
  /// Smallest cluster accepted by the default start [supervoxels].
  int min_cluster_supervoxels = 3;
};

/// \brief How the object is picked in the first frame.
struct ObjectSelection {
  /// \brief Which of the fields below points out the object.
  enum class Mode {
    /// After removing the dominant plane (RANSAC), the cluster of adjacent,
    /// colour-consistent supervoxels (chromaticities within
    /// TrackingSettings::max_chroma_distance) at the image centre (the surface its centre pixel sees).
    Auto,
    Box,    ///< supervoxels whose centroid is inside `box` (world frame)
    Image,  ///< supervoxels whose centroid projects inside `rect` or onto a non-zero `mask` pixel
  };
  Mode mode = Mode::Auto;  ///< how the object is found
  Eigen::AlignedBox3d box;         ///< world frame [m], for Mode::Box (also the first crop)
  Eigen::AlignedBox2i rect;        ///< pixels [u0, v0] .. [u1, v1] inclusive, for Mode::Image
  std::vector<std::uint8_t> mask;  ///< width x height, non-zero = object; overrides `rect`
};

/// \brief All settings of the front end.
struct PerceptionSettings {
  CloudSettings cloud;  ///< back-projection; its voxel resolution is supervoxels.voxel_resolution
  SupervoxelSettings supervoxels;  ///< the supervoxel stage
  TrackingSettings tracking;        ///< selection in the first frame, tracking from frame to frame
  double r_sphere = EstimatorSettings{}.r_sphere;  ///< R_sphere = d_pref (paper eq. 2) [m]
  double crop_margin = 0.1;  ///< crop radius = r_sphere + crop_margin around the previous C [m]
  double max_depth = 3.0;    ///< points farther along the optical axis are dropped [m], at most kMaxLength
  /// The object's OBB (PCA of its voxels) grows by this on every side [m]:
  /// what lies inside it, in contact with the object (contact_distance), but
  /// is not object is interacting (a holding hand).
  double obb_margin = 0.03;
  /// A supervoxel inside the augmented OBB is interacting when one of its
  /// voxels lies within this distance of an object voxel (seen or
  /// remembered) [m]: in contact, within two voxels. What the box holds farther
  /// from the object (in the hollow of a bent cloth, over its fold) is an
  /// occluder (README, "What perception costs").
  double contact_distance = 0.015;
  /// The holder's body beyond the augmented OBB is interacting too. The
  /// holder is what is interacting when the object is selected; later
  /// frames find it again inside the box within max_motion of where it was
  /// (moved with the object), in contact or not, and its body grows from
  /// there through supervoxels in the
  /// sphere, not of the support plane, in contact (contact_distance, voxel
  /// to voxel) and of its chromaticity (TrackingSettings::max_chroma_distance).
  /// The wrist and arm of a hand holding the object move with it; the
  /// paper's classes (false) make them occluders, which send the camera
  /// away from views they seldom block. A body that comes to touch the
  /// object later keeps the paper's classes (a hand over a cloth's fold:
  /// interacting where it touches, an occluder beyond), or, when it was an
  /// occluder in the frame before (it came from elsewhere: a box lingering
  /// against the object's face), is an occluder where it touches too, until
  /// it has taken the object: once the object has moved 2 cm since the body first
  /// touched it, and the body's voxels of then, carried by the object's
  /// estimated motion, lie on the body at less than half the distance of
  /// the same voxels left where they were, it is the holder. The support
  /// plane's supervoxels in the sphere that the body touches are
  /// interacting too: its base (a hand resting on a table of its colour
  /// looks like the plane there) or the table under it; on `sweep`, with
  /// the body's base an occluder, 1-5 voxels of it were the frame's only
  /// occluders after the arm had gone (occluder precision 0 there).
  bool holder_body = true;
  /// The paper's classification makes every non-object supervoxel inside
  /// the sphere an occluder (or, inside the OBB, interacting), the table the
  /// object stands on included. false: supervoxels of the support plane
  /// found in the first frame are background (as the simulator's
  /// ground-truth problem, which lists only occluding bodies).
  bool support_plane_occludes = true;
  /// An occluder the image border cuts goes on beyond it (a hand's arm, a
  /// tool's handle): the sensor only sees where it enters the view. Each
  /// occluder supervoxel within one seed resolution of the border is
  /// continued outwards, at its depth, every seed resolution until it
  /// leaves the sphere; the estimator so does not look for a view through
  /// the part of the arm it cannot see. false: only what the frame shows
  /// (the paper's reading).
  bool beyond_view = true;
  /// The paper assumes the first frame sees the whole object. When an
  /// occluder (nearer the camera than obb_margin) cuts the object's outline
  /// in the first frame, on no more of it than the object's own outline
  /// shows (one side cut, not an object seen through a cage), the object
  /// is presumed to go on behind it: from each cut the plane of the seen
  /// surface is continued, voxel by voxel and across the line of sight,
  /// while something nearer the camera (not the support plane) hides it and
  /// at most as far as the seen part is wide. Those voxels join the memory
  /// as hidden (vertices of the problem, part of C and the OBB), are
  /// recognised as object when they come into view and dropped when a
  /// frame shows them not there. Ends once a frame shows the object with no
  /// such cut. false: only what has been seen (the paper's reading).
  bool behind_occluders = true;
  /// Where the object and the classes come from.
  enum class Classes {
    /// The paper's front end: the object tracked from frame to frame, the
    /// other supervoxels classified by the augmented OBB and the sphere.
    Segmentation,
    /// The frame's ground-truth labels (RgbdFrame::labels) in place of
    /// segmentation and classification: each supervoxel is cut where the
    /// labels change (VoxelLabels); the object is what is labelled object,
    /// the occluders what belongs to an occluding body inside the sphere,
    /// the holder what is labelled interacting; the support and unlabelled
    /// points are classified by the paper's rule. Everything else (memory
    /// of the hidden part, its motion, behind_occluders, beyond_view) is the
    /// same front end. What a perfect classifier of this sensor's frames
    /// would give: the limit of any front end from this sensor.
    Labels,
  };
  Classes classes = Classes::Segmentation;  ///< where the classes come from
  ObjectSelection selection;  ///< how the object is found in the first frame
};

/// \brief Whether the object was found in a frame.
enum class TrackingStatus {
  Initialised,  ///< first frame: the object was selected
  Tracking,     ///< followed from the previous frame
  Lost,         ///< not found (too few voxels near its last state, or no valid selection)
};

/// \brief The class of a supervoxel (paper section II-B).
enum class SupervoxelClass { Object, Interacting, Occluder, Background };

/// \brief One supervoxel of a frame (world frame).
struct SupervoxelInfo {
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();  ///< v_n [m]
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();   ///< unit, towards the camera that saw it
  Eigen::Vector3f colour = Eigen::Vector3f::Zero();    ///< mean R, G, B in [0, 255]
  int voxel_count = 0;       ///< occupied voxels it holds
  bool normal_valid = true;  ///< false when PCL gave no finite normal (not used as object vertex)
  SupervoxelClass label = SupervoxelClass::Background;  ///< its class in this frame
};

/// \brief An oriented box: centre, axes (columns, right-handed) and half extents [m].
struct OrientedBox {
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();         ///< world frame [m]
  Eigen::Matrix3d axes = Eigen::Matrix3d::Identity();       ///< unit axes (columns), world frame
  Eigen::Vector3d half_extents = Eigen::Vector3d::Zero();  ///< along each axis [m]
  /// True when world point p is inside (boundary included).
  [[nodiscard]] bool contains(const Eigen::Vector3d& p) const {
    const Eigen::Vector3d local = axes.transpose() * (p - centre);
    return (local.cwiseAbs().array() <= half_extents.array()).all();
  }
};

/// \brief Counts of one frame.
struct PerceptionCounts {
  std::size_t valid_pixels = 0;    ///< pixels with depth (after the stride)
  std::size_t cropped_points = 0;  ///< inside the working volume
  std::size_t voxels = 0;          ///< occupied voxels given to the supervoxel stage
  std::size_t supervoxels = 0;      ///< supervoxels of the frame
  std::size_t adjacency_edges = 0;  ///< pairs within R_adj
  std::size_t object = 0;       ///< object supervoxels
  std::size_t interacting = 0;  ///< interacting supervoxels (in contact with the object, in its augmented OBB)
  std::size_t occluders = 0;    ///< occluder supervoxels (inside the sphere, outside the box)
  std::size_t beyond_view = 0;  ///< occluder points added beyond the image border (PerceptionSettings::beyond_view)
  std::size_t object_voxels = 0;  ///< seen in this frame
  std::size_t hidden_voxels = 0;  ///< remembered behind occluders, added to the object cloud
  std::size_t hidden_vertices = 0;  ///< vertices of the remembered hidden voxels added to the problem (hidden_vertices)
  std::size_t presumed_voxels = 0;  ///< voxels presumed behind an occluder this frame (PerceptionSettings::behind_occluders)
};

/// \brief Wall time of each stage [ms].
struct PerceptionTimings {
  double cloud = 0.0;        ///< back-projection, crop, voxelisation
  double supervoxels = 0.0;  ///< pcl::SupervoxelClustering
  double adjacency = 0.0;    ///< R_adj graph
  double tracking = 0.0;     ///< selection or frame-to-frame tracking
  double classify = 0.0;     ///< PCA, OBB, interacting/occluders, ViewProblem
  double total = 0.0;        ///< the whole frame
};

/// \brief Everything the front end found in one frame (world frame [m]).
struct PerceptionResult {
  TrackingStatus status = TrackingStatus::Lost;  ///< whether the object was found
  /// The estimator's input: object supervoxels and normals, occluders,
  /// centroid C, PCA axes, camera position. Empty when status is Lost.
  ViewProblem problem;
  std::vector<SupervoxelInfo> supervoxels;             ///< every supervoxel, labelled
  std::vector<std::pair<int, int>> adjacency;          ///< edges (i < j) within R_adj
  std::vector<Eigen::Vector3f> voxels;                 ///< every clustered voxel
  std::vector<int> voxel_owner;                        ///< its supervoxel index
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();  ///< C: mean of the object voxels
  Eigen::Matrix3d axes =
      Eigen::Matrix3d::Identity();  ///< e1, e2, e3 (columns), PCA of the object voxels
  OrientedBox obb;                  ///< the augmented OBB
  Eigen::Isometry3d wMc = Eigen::Isometry3d::Identity();  ///< pose of the camera that saw the frame
  /// The support plane (world frame) the first frame's selection fitted,
  /// and its colour; none before it, or when it found none.
  std::optional<SupportPlane> support_plane;
  /// The remembered object voxels this frame does not show (behind
  /// something, out of the image, presumed behind an occluder) [m].
  std::vector<Eigen::Vector3f> hidden;
  PerceptionCounts counts;    ///< what each stage found
  PerceptionTimings timings;  ///< what each stage took
  std::string message;  ///< why the object is lost, when it is
};

/**
 * \brief What a result tells the loop: the problem (none when the object is
 *        lost) with the occluders seen in the frame, the ones beyond the
 *        image border as presumed, and the object's voxels seen in the frame
 *        times a voxel's face as the shown area [m²]. Its age is left 0.
 * \param result the front end's result for the frame
 * \param voxel the front end's voxel edge (SupervoxelSettings::voxel_resolution) [m]
 */
[[nodiscard]] Observation observation(const PerceptionResult& result, double voxel);

/// \brief The status's word in files and on the terminal: initialised, tracking, lost.
[[nodiscard]] const char* to_string(TrackingStatus status);
/// \brief The class's word: object, interacting, occluder, background.
[[nodiscard]] const char* to_string(SupervoxelClass label);
/// \brief The word of PerceptionSettings::Classes: segmentation, labels.
[[nodiscard]] const char* to_string(PerceptionSettings::Classes classes);
/// \brief The word of SupervoxelSettings::Method: ofv, pcl.
[[nodiscard]] const char* to_string(SupervoxelSettings::Method method);

/// \brief Throws std::invalid_argument naming the setting and value when a
/// setting is out of range (non-positive resolutions, alpha outside [1, 1.5], ...).
void validate(const PerceptionSettings& settings);

/// \brief The front end's settings for an estimator: its r_sphere and, as
///        the supervoxel seed resolution, its r_seed; the rest from `base`.
[[nodiscard]] PerceptionSettings perception_settings(const EstimatorSettings& estimator,
                                                     PerceptionSettings base = {});

/// \brief The front end's settings a user sets by name (`--set`, scenario
///        files, grids): supervoxels, beyond_view, behind_occluders, grow_revealed, holder_body.
[[nodiscard]] const SettingsTable<PerceptionSettings>& perception_settings_table();

/**
 * \brief Follows one object through a sequence of RGB-D frames.
 *
 * Not thread-safe; one instance per sequence. Buffers are reused between frames.
 */
class Perception {
 public:
  /// \throws std::invalid_argument for invalid settings (see validate()).
  explicit Perception(const PerceptionSettings& settings);
  ~Perception();
  Perception(Perception&&) noexcept;             ///< moves the front end and what it remembers
  Perception& operator=(Perception&&) noexcept;  ///< moves the front end and what it remembers
  Perception(const Perception&) = delete;
  Perception& operator=(const Perception&) = delete;

  /// \brief Processes the next frame.
  /// \throws std::invalid_argument if the frame's buffers disagree with its intrinsics.
  [[nodiscard]] PerceptionResult process(const RgbdFrame& frame);

  /// \brief Forgets the object: the next frame starts again from the selection.
  void reset();

  /// \brief The settings it was made with.
  [[nodiscard]] const PerceptionSettings& settings() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/**
 * \brief The front end as the loop's ofv::Observer: each frame through
 *        Perception::process, then observation(); the whole result of the
 *        last frame stays readable (for scores, pictures and displays).
 */
class PerceptionObserver final : public Observer {
 public:
  /// \throws std::invalid_argument for invalid settings (see validate()).
  explicit PerceptionObserver(const PerceptionSettings& settings);
  [[nodiscard]] Observation observe(const RgbdFrame& frame) override;
  /// \brief The front end's result of the last observe() (empty before the first).
  [[nodiscard]] const PerceptionResult& last() const { return last_; }
  /// \brief The front end's settings.
  [[nodiscard]] const PerceptionSettings& settings() const { return perception_.settings(); }

 private:
  Perception perception_;
  PerceptionResult last_;
};

}  // namespace ofv::perception

/// \cond OFV_OLD_NAMES
// The names of ofv 0.1, kept for one release: use ofv::perception::.
namespace ofv {
using Perception [[deprecated("use ofv::perception::Perception")]] = perception::Perception;
using PerceptionObserver [[deprecated("use ofv::perception::PerceptionObserver")]] = perception::PerceptionObserver;
using SupervoxelClass [[deprecated("use ofv::perception::SupervoxelClass")]] = perception::SupervoxelClass;
using TrackingStatus [[deprecated("use ofv::perception::TrackingStatus")]] = perception::TrackingStatus;
using perception::observation;
using perception::perception_settings;
using perception::perception_settings_table;
using ObjectSelection [[deprecated("use ofv::perception::ObjectSelection")]] = perception::ObjectSelection;
using OrientedBox [[deprecated("use ofv::perception::OrientedBox")]] = perception::OrientedBox;
using PerceptionCounts [[deprecated("use ofv::perception::PerceptionCounts")]] = perception::PerceptionCounts;
using PerceptionResult [[deprecated("use ofv::perception::PerceptionResult")]] = perception::PerceptionResult;
using PerceptionSettings [[deprecated("use ofv::perception::PerceptionSettings")]] = perception::PerceptionSettings;
using PerceptionTimings [[deprecated("use ofv::perception::PerceptionTimings")]] = perception::PerceptionTimings;
using SupervoxelInfo [[deprecated("use ofv::perception::SupervoxelInfo")]] = perception::SupervoxelInfo;
using SupervoxelSettings [[deprecated("use ofv::perception::SupervoxelSettings")]] = perception::SupervoxelSettings;
using TrackingSettings [[deprecated("use ofv::perception::TrackingSettings")]] = perception::TrackingSettings;
using perception::to_string;
using perception::validate;
}  // namespace ofv
/// \endcond
