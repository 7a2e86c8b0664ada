// Recorded sequences: TUM RGB-D layout and PCD sequences, written and read back.
#include "ofv/perception/perception.h"
#include "ofv/sources/pcd_sequence.h"
#include "ofv/sources/tum_sequence.h"

#include "scratch.h"
#include "synthetic_scene.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace fs = std::filesystem;

namespace ofv {
namespace {

/// A fresh directory under the test's temporary directory.
fs::path scratch(const std::string& name) {
  const fs::path dir = fs::path(test::scratch_dir()) / ("ofv_perception_" + name);
  fs::remove_all(dir);
  return dir;
}

/// Frames of the table-and-case world seen from a camera moving sideways.
std::vector<RgbdFrame> episode(int frames, int width = 320) {
  const test::SyntheticScene scene = test::table_and_case();
  std::vector<RgbdFrame> out;
  for (int k = 0; k < frames; ++k) {
    const Eigen::Vector3d target(0.0, 0.0, 0.0675);
    const Eigen::Isometry3d wMc =
        test::look_at(target + Eigen::Vector3d(0.02 * k, -0.45, 0.22), target);
    out.push_back(scene.render(test::vga(width), wMc, nullptr, 0.1 * k));
  }
  return out;
}

void expect_same_frame(const RgbdFrame& read, const RgbdFrame& written, double depth_step) {
  EXPECT_NEAR(read.timestamp, written.timestamp, 1e-6);
  EXPECT_EQ(read.intrinsics.width, written.intrinsics.width);
  EXPECT_NEAR(read.intrinsics.fx, written.intrinsics.fx, 1e-6);
  EXPECT_NEAR(read.intrinsics.cy, written.intrinsics.cy, 1e-6);
  EXPECT_TRUE(read.wMc.isApprox(written.wMc, 1e-6));
  ASSERT_EQ(read.depth.size(), written.depth.size());
  for (std::size_t i = 0; i < read.depth.size(); ++i) {
    ASSERT_NEAR(read.depth[i], written.depth[i], depth_step) << "pixel " << i;
  }
  EXPECT_EQ(read.rgb, written.rgb);
}

TEST(TumSequence, WritesAndReadsBackFrames) {
  const fs::path dir = scratch("tum");
  const auto frames = episode(3);
  {
    TumSequenceWriter writer(dir.string());
    for (const RgbdFrame& f : frames) {
      writer.write(f);
    }
    EXPECT_EQ(writer.count(), 3u);
  }
  EXPECT_TRUE(fs::exists(dir / "rgb.txt"));
  EXPECT_TRUE(fs::exists(dir / "depth.txt"));
  EXPECT_TRUE(fs::exists(dir / "groundtruth.txt"));
  TumSequenceSource source(dir.string());
  EXPECT_EQ(source.size(), 3u);
  EXPECT_NE(source.describe().find(dir.string()), std::string::npos);
  for (const RgbdFrame& f : frames) {
    const auto read = source.next();
    ASSERT_TRUE(read);
    expect_same_frame(*read, f, 0.5 / 5000.0 + 1e-6);
  }
  EXPECT_FALSE(source.next());
}

// ofv's own recordings keep a frame's ground truth: its labels and the
// object's centroid; frames without them read back without them.
TEST(TumSequence, WritesAndReadsBackTheGroundTruth) {
  const fs::path dir = scratch("tum_truth");
  auto frames = episode(3);
  for (std::size_t k = 0; k < 2; ++k) {
    RgbdFrame& f = frames[k];
    f.labels.resize(f.depth.size());
    for (std::size_t i = 0; i < f.labels.size(); ++i) f.labels[i] = static_cast<std::uint16_t>((i * 7 + k) % 13);
    f.object_centroid = Eigen::Vector3d(0.1 * static_cast<double>(k), -0.2, 0.5);
  }
  {
    TumSequenceWriter writer(dir.string());
    for (const RgbdFrame& f : frames) writer.write(f);
  }
  EXPECT_TRUE(fs::exists(dir / "labels.txt"));
  EXPECT_TRUE(fs::exists(dir / "object.txt"));
  TumSequenceSource source(dir.string());
  for (std::size_t k = 0; k < 2; ++k) {
    const auto read = source.next();
    ASSERT_TRUE(read);
    EXPECT_EQ(read->labels, frames[k].labels);
    ASSERT_TRUE(read->object_centroid);
    EXPECT_LT((*read->object_centroid - *frames[k].object_centroid).norm(), 1e-9);
  }
  const auto last = source.next();  // written without labels: none read; the centroid held from the last
  ASSERT_TRUE(last);
  EXPECT_TRUE(last->labels.empty());
  // A label image of the wrong kind is refused, naming it.
  const fs::path first_labels = dir / "labels" / "0.000000.png";
  fs::copy_file(dir / "rgb" / "0.000000.png", first_labels, fs::copy_options::overwrite_existing);
  TumSequenceSource broken(dir.string());
  try {
    (void)broken.next();
    ADD_FAILURE() << "a colour PNG was read as labels";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("label image"), std::string::npos) << e.what();
  }
}

TEST(TumSequence, AssociatesNearestColourAndInterpolatesPoses) {
  const fs::path dir = scratch("tum_assoc");
  const auto frames = episode(2);
  {
    TumSequenceWriter writer(dir.string());
    writer.write(frames[0]);
    writer.write(frames[1]);
  }
  // Shift the second depth stamp by 5 ms (colour still associated) and drop the
  // first colour entry (its depth frame then has no colour); ground truth at
  // t = 0 and 0.1 only, so the pose at 0.105 is the last one.
  {
    std::ofstream(dir / "depth.txt")
        << "# x\n0.000000 depth/0.000000.png\n0.105000 depth/0.100000.png\n";
    std::ofstream(dir / "rgb.txt") << "0.100000 rgb/0.100000.png\n";
  }
  TumSequenceSource source(dir.string());
  const auto a = source.next();
  const auto b = source.next();
  ASSERT_TRUE(a && b);
  EXPECT_TRUE(a->rgb.empty());
  EXPECT_EQ(b->rgb, frames[1].rgb);
  EXPECT_NEAR(b->timestamp, 0.105, 1e-9);
  EXPECT_TRUE(b->wMc.isApprox(frames[1].wMc, 1e-6));

  const std::vector<StampedPose> poses{{0.0, frames[0].wMc}, {0.1, frames[1].wMc}};
  const Eigen::Isometry3d mid = interpolate_pose(poses, 0.05);
  EXPECT_TRUE(mid.translation().isApprox(
      0.5 * (frames[0].wMc.translation() + frames[1].wMc.translation()), 1e-9));
  EXPECT_NEAR(Eigen::AngleAxisd(mid.linear().transpose() * frames[0].wMc.linear()).angle(),
              Eigen::AngleAxisd(mid.linear().transpose() * frames[1].wMc.linear()).angle(), 1e-9);
}

TEST(TumSequence, BrokenInputsAreErrorsNamingThePath) {
  const auto message = [](auto&& f) {
    try {
      f();
    } catch (const std::exception& e) {
      return std::string(e.what());
    }
    return std::string("no exception");
  };
  const fs::path missing = scratch("tum_missing");
  EXPECT_NE(message([&] { TumSequenceSource s(missing.string()); }).find(missing.string()),
            std::string::npos);
  const fs::path dir = scratch("tum_broken");
  {
    TumSequenceWriter writer(dir.string());
    writer.write(episode(1)[0]);
    RgbdFrame same = episode(1)[0];
    EXPECT_THROW(writer.write(same), std::invalid_argument);  // timestamp does not increase
  }
  std::ofstream(dir / "depth" / "0.000000.png") << "not a png";
  TumSequenceSource source(dir.string());
  EXPECT_NE(message([&] { (void)source.next(); }).find("0.000000.png"), std::string::npos);
  std::ofstream(dir / "groundtruth.txt") << "0.0 1 2 3\n";
  EXPECT_NE(message([&] { TumSequenceSource s(dir.string()); }).find("groundtruth.txt:1"),
            std::string::npos);
  // A quaternion of norm 2 is not a rotation (within kQuaternionTolerance).
  std::ofstream(dir / "groundtruth.txt") << "0.0 1 2 3 0 0 0 2\n";
  const std::string norm = message([&] { TumSequenceSource s(dir.string()); });
  EXPECT_NE(norm.find("groundtruth.txt:1: quaternion norm 2"), std::string::npos) << norm;
}

TEST(SequenceFiles, TextIsParsedAsTheFileIs) {
  const std::string poses = "# t tx ty tz qx qy qz qw\n0.2 1 2 3 0 0 0 1\n\n0.1 4 5 6 0 0 1 0\n";
  const fs::path file = scratch("pose_text.txt");
  std::ofstream(file) << poses;
  std::istringstream in(poses);
  const auto parsed = parse_pose_file(in, "text");
  const auto read = read_pose_file(file.string());
  ASSERT_EQ(parsed.size(), 2u);
  ASSERT_EQ(read.size(), 2u);
  for (std::size_t k = 0; k < 2; ++k) {
    EXPECT_EQ(parsed[k].time, read[k].time);
    EXPECT_TRUE(parsed[k].wMc.isApprox(read[k].wMc, 0.0));
  }
  EXPECT_EQ(parsed[0].time, 0.1);  // sorted by time
  std::istringstream bad_pose("0.1 1 2 3 0 0 0\n");
  EXPECT_THROW((void)parse_pose_file(bad_pose, "text"), std::runtime_error);

  std::istringstream intrinsics("# w h fx fy cx cy\n16 12 15 15 7.5 5.5\n");
  EXPECT_EQ(parse_intrinsics_file(intrinsics, "text").height, 12);
  std::istringstream too_wide("5000 12 15 15 7.5 5.5\n");
  EXPECT_THROW((void)parse_intrinsics_file(too_wide, "text"), std::runtime_error);

  std::istringstream list("# timestamp filename\n2 depth/2.png\n1 depth/1.png\n");
  const auto files = parse_timestamp_list(list, "depth.txt");
  ASSERT_EQ(files.size(), 2u);
  EXPECT_EQ(files[0].file, "depth/1.png");
  std::istringstream bad_list("nan depth/1.png\n");
  try {
    (void)parse_timestamp_list(bad_list, "depth.txt");
    FAIL() << "expected an error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("depth.txt:1"), std::string::npos) << e.what();
  }
  // A long bad line is quoted shortened, so that the error stays one short line.
  std::istringstream long_line("0.1 " + std::string(100000, '7') + "\n");
  try {
    (void)parse_pose_file(long_line, "poses.txt");
    FAIL() << "expected an error";
  } catch (const std::runtime_error& e) {
    EXPECT_LT(std::string(e.what()).size(), 200U);
    EXPECT_NE(std::string(e.what()).find("poses.txt:1"), std::string::npos) << e.what();
  }
}

TEST(SequenceFiles, APoseFileWrittenReadsBackTheSame) {
  std::vector<StampedPose> poses;
  for (int k = 0; k < 10; ++k) {
    StampedPose p;
    p.time = k / 30.0;
    p.wMc = Eigen::Translation3d(0.3 * std::sin(0.1 * k), 0.01 * k, 0.5) *
            Eigen::AngleAxisd(0.02 * k, Eigen::Vector3d(0.3, 1.0, 0.2).normalized());
    poses.push_back(p);
  }
  const fs::path file = scratch("written_poses.txt");
  write_pose_file(file.string(), poses, "camera pose wMc");
  const auto back = read_pose_file(file.string());
  ASSERT_EQ(back.size(), poses.size());
  for (std::size_t k = 0; k < poses.size(); ++k) {
    EXPECT_DOUBLE_EQ(back[k].time, poses[k].time);
    EXPECT_TRUE(back[k].wMc.isApprox(poses[k].wMc, 1e-12));
  }
  EXPECT_THROW(write_pose_file((scratch("no_such_folder") / "poses.txt").string(), poses, "x"), std::runtime_error);
}

TEST(PcdSequence, HeaderIsCheckedInMemoryAsInTheFile) {
  const std::string header =
      "VERSION 0.7\nFIELDS x y z rgb\nSIZE 4 4 4 4\nTYPE F F F F\nCOUNT 1 1 1 1\n"
      "WIDTH 2\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS 2\nDATA binary\n";
  const std::string whole = header + std::string(32, '\0');
  std::istringstream good(whole);
  EXPECT_NO_THROW(check_pcd_header(good, whole.size(), "mem.pcd"));
  const fs::path file = scratch("header.pcd");
  std::ofstream(file, std::ios::binary) << whole;
  EXPECT_NO_THROW(check_pcd_header(file.string()));
  // One point short of the header's two: refused, naming the source.
  const std::string cut = header + std::string(31, '\0');
  std::istringstream short_data(cut);
  try {
    check_pcd_header(short_data, cut.size(), "mem.pcd");
    FAIL() << "expected an error";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("mem.pcd: invalid PCD header: DATA binary"), std::string::npos) << e.what();
  }
}

TEST(PcdSequence, WritesAndReadsBackFramesAndFitsIntrinsics) {
  const fs::path dir = scratch("pcd");
  const auto frames = episode(2);
  {
    PcdSequenceWriter writer(dir.string());
    for (const RgbdFrame& f : frames) {
      writer.write(f);
    }
  }
  {
    PcdSequenceSource source(dir.string());
    EXPECT_EQ(source.size(), 2u);
    for (const RgbdFrame& f : frames) {
      const auto read = source.next();
      ASSERT_TRUE(read);
      expect_same_frame(*read, f, 1e-6);
    }
    EXPECT_FALSE(source.next());
  }
  // Without intrinsics.txt the intrinsics come from the organised points.
  fs::remove(dir / "intrinsics.txt");
  PcdSequenceSource fitted(dir.string());
  const auto read = fitted.next();
  ASSERT_TRUE(read);
  EXPECT_NEAR(read->intrinsics.fx, frames[0].intrinsics.fx, 1e-2);
  EXPECT_NEAR(read->intrinsics.cx, frames[0].intrinsics.cx, 1e-2);
  EXPECT_NEAR(read->intrinsics.fy, frames[0].intrinsics.fy, 1e-2);
  EXPECT_NEAR(read->intrinsics.cy, frames[0].intrinsics.cy, 1e-2);
  // A pose file that does not match the files is an error naming it.
  std::ofstream(dir / "poses.txt") << "0 0 0 0 0 0 0 1\n";
  try {
    PcdSequenceSource s(dir.string());
    FAIL() << "expected an error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("poses.txt"), std::string::npos);
  }
}

TEST(TumSequence, PerceptionOnARecordingMatchesTheLiveFrames) {
  const fs::path dir = scratch("tum_perception");
  const auto frames = episode(3, 640);
  {
    TumSequenceWriter writer(dir.string());
    for (const RgbdFrame& f : frames) {
      writer.write(f);
    }
  }
  perception::Perception live{perception::PerceptionSettings{}};
  perception::Perception replay{perception::PerceptionSettings{}};
  TumSequenceSource source(dir.string());
  for (const RgbdFrame& f : frames) {
    const auto read = source.next();
    ASSERT_TRUE(read);
    const perception::PerceptionResult a = live.process(f);
    const perception::PerceptionResult b = replay.process(*read);
    ASSERT_NE(a.status, perception::TrackingStatus::Lost);
    ASSERT_EQ(a.status, b.status);
    // 0.2 mm depth quantisation can flip a boundary supervoxel, nothing more:
    // the centroids agree within the front end's 1 cm accuracy.
    EXPECT_LE((a.centroid - b.centroid).norm(), 0.01);
    EXPECT_NEAR(static_cast<double>(a.counts.object), static_cast<double>(b.counts.object),
                0.1 * static_cast<double>(a.counts.object));
  }
}

}  // namespace
}  // namespace ofv
