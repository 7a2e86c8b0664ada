/**
 * \file open_source.h
 * \brief Opens the frame source a user names: a recording or a device.
 */
#pragma once

#include "ofv/frame_source.h"

#include <memory>
#include <string>

namespace ofv {

/**
 * \brief Opens the frame source named by `source`, one of:
 *
 * - `DIR` holding `depth.txt`: a TUM RGB-D sequence (TumSequenceSource);
 * - `DIR` holding `*.pcd` files: a PCD sequence (PcdSequenceSource);
 * - `FILE.oni`: an OpenNI2 recording (OpenNi2Source; camera poses from
 *   `FILE.oni.poses.txt` when present);
 * - `openni2://URI`: a live OpenNI2 device; `openni2://` alone opens the
 *   first device found.
 *
 * \code
 * const auto source = ofv::open_source("rgbd_dataset_freiburg1_xyz", -1.0f);
 * while (const auto frame = source->next()) { ... }
 * \endcode
 *
 * \param source the folder, file or URI.
 * \param playback_speed playback speed of a `.oni` recording
 *        (OpenNi2Options::playback_speed: 1 real time, skipping the
 *        frames that are past due; 0 or -1 every frame, as soon as next()
 *        asks); ignored by the other sources.
 * \param source_poses false when the camera poses come from elsewhere
 *        (RGB-D odometry): a TUM sequence without groundtruth.txt is then
 *        read with the identity for wMc (TumSequenceOptions::require_poses).
 * \throws std::invalid_argument naming `source` when it is none of the forms
 *         above (a missing `.oni` file or folder, a folder of neither kind).
 * \throws std::runtime_error from the source's constructor when a sequence is
 *         broken, a recording cannot be played or OpenNI2 cannot open the device.
 */
std::unique_ptr<FrameSource> open_source(const std::string& source, float playback_speed, bool source_poses = true);

}  // namespace ofv
