/**
 * \file picture.h
 * \brief A picture of one perceived frame, in the spirit of Fig. 6 of
 *        Cuiral-Zueco and López-Nicolás.
 */
#pragma once

#include "ofv/estimator.h"
#include "ofv/perception/perception.h"
#include "ofv/rgbd_frame.h"

#include <optional>
#include <string>

namespace ofv::perception {

/**
 * \brief Draws the scene of one frame and saves it as an 800 x 600 PNG.
 *
 * The scene is seen by a virtual observer beside and behind the real camera,
 * 2.4 `r_sphere` from C: object voxels (green) and supervoxel normals (red),
 * the rays from C through the object vertices to the sphere (blue), the
 * augmented OBB, interacting voxels (yellow), occluders (red squares), the
 * sphere (three great circles), the real camera t_real and, with an
 * estimate, t0 (cyan) and tf (magenta). The camera image is inset top left,
 * with the object, interacting and occluder supervoxels marked; the status,
 * counts and times are written underneath.
 *
 * \param path the PNG file to write.
 * \param frame the frame given to Perception::process().
 * \param result what Perception::process() returned for it.
 * \param estimate the view estimated from result.problem, if any.
 * \param r_sphere R_sphere [m], the radius of the sphere drawn around C.
 * \throws std::runtime_error naming `path` when the file cannot be written.
 */
void save_perception_picture(const std::string& path, const RgbdFrame& frame,
                             const PerceptionResult& result,
                             const std::optional<ViewEstimate>& estimate, double r_sphere);

}  // namespace ofv::perception

/// \cond OFV_OLD_NAMES
// The names of ofv 0.1, kept for one release: use ofv::perception::.
namespace ofv {
using perception::save_perception_picture;
}  // namespace ofv
/// \endcond
