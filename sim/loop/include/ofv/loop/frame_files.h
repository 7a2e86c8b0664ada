/**
 * \file frame_files.h
 * \brief One simulated frame as files for people (`ofv render`): colour,
 *        depth and label pictures, and the world-frame point cloud.
 */
#pragma once

#include "ofv/rgbd_frame.h"
#include "ofv/sim/renderer.h"

#include <string>
#include <vector>

namespace ofv {

/**
 * \brief Writes `colour.png`, `depth.png` (turbo colour map from 0 to
 *        `max_depth`, black where missing) and `labels.png` (object blue,
 *        interacting green, table brown, occluders red hues) into `dir`.
 * \return the names of the files written.
 * \throws std::runtime_error when a file cannot be written.
 */
std::vector<std::string> write_frame_pictures(const std::string& dir, const sim::RenderedFrame& frame, double max_depth);

/**
 * \brief Writes the frame's points in the world frame with their colours, as
 *        ASCII PLY when `path` ends in `.ply`, else as ASCII PCD.
 * \throws std::runtime_error when the file cannot be written.
 */
void write_world_cloud(const RgbdFrame& frame, const std::string& path);

}  // namespace ofv
