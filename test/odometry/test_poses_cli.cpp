// `ofv perceive --poses` end to end through the `ofv` binary, on a short
// recording of a simulated episode (`ofv simulate --record`).
#include "cli_run.h"

#include "ofv/sources/sequence_files.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>

namespace ofv {
namespace {

namespace fs = std::filesystem;

/// A 1 s recording of dvd-static, made once per test process.
const std::string& recording() {
  static const std::string dir = [] {
    const std::string d = (fs::path(test::scratch_dir()) / "dvd-static").string();
    const CommandRun r = run("simulate dvd-static --set duration=1 --no-pictures --record " + d + " --out " + d +
                             "-episode >/dev/null");
    EXPECT_EQ(r.code, 0) << r.err;
    return d;
  }();
  return dir;
}

TEST(PosesCli, OdometryWritesPosesAndPrintsTheErrors) {
  const std::string out = (fs::path(test::scratch_dir()) / "odometry").string();
  const CommandRun r = run("perceive " + recording() + " --poses odometry --out " + out);
  ASSERT_EQ(r.code, 0) << r.err;
  const auto frames = read_pose_file(recording() + "/groundtruth.txt");
  const auto poses = read_pose_file(out + "/poses.txt");
  EXPECT_EQ(poses.size(), frames.size());
  EXPECT_TRUE(fs::exists(out + "/frame_000001.json"));
  EXPECT_NE(file_text(out + "/frame_000001.json").find("\"odometry\""), std::string::npos);
  // "ATE 0.41 mm" on stderr: small on a still scene. (No std::regex: GCC 12
  // warns inside it under the sanitizer build's -Werror.)
  const std::size_t at = r.err.find("ATE ");
  ASSERT_NE(at, std::string::npos) << r.err;
  char* end = nullptr;
  const double ate = std::strtod(r.err.c_str() + at + 4, &end);
  ASSERT_EQ(std::string(end, 3), " mm") << r.err;
  EXPECT_LT(ate, 2.0) << r.err;
  // Every frame of a still scene is ok: the same measure over them.
  EXPECT_NE(r.err.find("frames called ok: " + std::to_string(frames.size()) + ", their ATE "), std::string::npos)
      << r.err;
}

TEST(PosesCli, SourcePosesAreTheRecordingsOwn) {
  const std::string out = (fs::path(test::scratch_dir()) / "source").string();
  const CommandRun r = run("perceive " + recording() + " --poses source --max-frames 3 --out " + out);
  ASSERT_EQ(r.code, 0) << r.err;
  const auto truth = read_pose_file(recording() + "/groundtruth.txt");
  const auto poses = read_pose_file(out + "/poses.txt");
  ASSERT_EQ(poses.size(), 3u);
  for (std::size_t k = 0; k < poses.size(); ++k) EXPECT_TRUE(poses[k].wMc.isApprox(truth[k].wMc, 1e-9));
}

TEST(PosesCli, ARecordingWithoutPosesNeedsOdometryAndGetsItsMotion) {
  // A TUM folder without groundtruth.txt (a handheld sensor, no tracker):
  // odometry gives its poses from the identity; the source's own cannot.
  const fs::path bare = fs::path(test::scratch_dir()) / "without_poses";
  fs::remove_all(bare);
  fs::copy(recording(), bare, fs::copy_options::recursive);
  fs::remove(bare / "groundtruth.txt");
  const CommandRun refused = run("perceive " + bare.string() + " --max-frames 3");
  EXPECT_EQ(refused.code, 2) << refused.err;
  EXPECT_NE(refused.err.find("groundtruth.txt"), std::string::npos) << refused.err;
  EXPECT_NE(refused.err.find("--poses odometry"), std::string::npos) << refused.err;

  const std::string out = (fs::path(test::scratch_dir()) / "without_poses_out").string();
  const CommandRun r = run("perceive " + bare.string() + " --poses odometry --out " + out);
  ASSERT_EQ(r.code, 0) << r.err;
  const auto truth = read_pose_file(recording() + "/groundtruth.txt");
  const auto poses = read_pose_file(out + "/poses.txt");
  ASSERT_EQ(poses.size(), truth.size());
  EXPECT_TRUE(poses.front().wMc.isApprox(Eigen::Isometry3d::Identity(), 1e-12));
  for (std::size_t k = 1; k < poses.size(); ++k) {  // the camera's motion from its first pose, within 2 mm
    const Eigen::Isometry3d moved = truth.front().wMc.inverse() * truth[k].wMc;
    EXPECT_LT((poses[k].wMc.translation() - moved.translation()).norm(), 0.002) << "frame " << k;
  }
}

TEST(PosesCli, UnknownMethodIsAUsageError) {
  const CommandRun r = run("perceive " + recording() + " --poses odometry:nope");
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.err.find("--poses"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("fast_icp"), std::string::npos) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
}

}  // namespace
}  // namespace ofv
