// A picture of one perceived frame in the spirit of the paper's Fig. 6.
#pragma once

#include "ofv/estimator.h"
#include "ofv/perception/perception.h"

#include <optional>
#include <string>

namespace ofv::cli {

/**
 * \brief Draws the frame's scene from a virtual observer beside and behind
 *        the real camera and saves it as PNG: object voxels and supervoxel
 *        normals, normals-to-sphere rays, the augmented OBB, interacting
 *        elements, occluders, the sphere, t_real, t0 and tf; the camera
 *        image with the object outlined is inset top left.
 * \throws std::runtime_error when the file cannot be written.
 */
void save_perception_picture(const std::string& path, const RgbdFrame& frame,
                             const PerceptionResult& result,
                             const std::optional<ViewEstimate>& estimate, double r_sphere);

}  // namespace ofv::cli
