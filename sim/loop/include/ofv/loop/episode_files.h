/**
 * \file episode_files.h
 * \brief What `ofv simulate` writes for an episode: trajectory.csv,
 *        metrics.json, camera and Fig. 6-style scene pictures at key moments,
 *        visibility.png, optionally episode.avi and the frames as a TUM RGB-D
 *        recording with the camera poses the episode had.
 */
#pragma once

#include "ofv/loop/episode.h"

#include <memory>
#include <string>
#include <vector>

namespace ofv {

/// \brief Which files EpisodeWriter writes besides trajectory.csv and metrics.json.
struct EpisodeFiles {
  bool pictures = true;  ///< PNG pictures at key moments and visibility.png (gnuplot)
  bool video = false;    ///< episode.avi: scene view and camera view side by side (MJPEG)
  /// When not empty: every frame the loop saw, as a TUM RGB-D sequence in
  /// this folder (colour, depth, groundtruth.txt with the camera poses it
  /// had, intrinsics.txt), which `ofv run --source` replays.
  std::string record_dir;
};

/**
 * \brief Writes an episode's files into a folder as the episode runs.
 *
 * \code
 * ofv::EpisodeWriter writer("out/ep", setup, {});
 * const auto outcome = ofv::run_episode(setup, [&](const auto& rec, const auto& d) { writer.observe(rec, d); });
 * writer.finish(outcome);
 * \endcode
 */
class EpisodeWriter {
 public:
  /// \throws std::runtime_error when the folder, the video or the recording cannot be created.
  EpisodeWriter(const std::string& dir, const EpisodeSetup& setup, const EpisodeFiles& files);
  ~EpisodeWriter();
  EpisodeWriter(const EpisodeWriter&) = delete;
  EpisodeWriter& operator=(const EpisodeWriter&) = delete;

  /// \brief Pictures at key moments (start, an occluder entering the sphere, the
  ///        visibility falling below 0.9, 1 s later, the end), video and recording frames.
  void observe(const StepRecord& record, const StepDetail& detail);

  /// \brief Writes trajectory.csv, metrics.json and visibility.png.
  /// \return the names of the files written, pictures included.
  std::vector<std::string> finish(const EpisodeOutcome& outcome);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace ofv
