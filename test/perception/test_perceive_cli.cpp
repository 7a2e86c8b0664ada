// End to end: `ofv perceive` on recordings written by the sources' writers.
#include "ofv/sources/openni2_source.h"
#include "ofv/sources/tum_sequence.h"

#include "cli_run.h"
#include "synthetic_scene.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace fs = std::filesystem;

namespace ofv {
namespace {

/// Frame 0 sees the case alone; then a hand grips it and an arm passes in front.
std::vector<RgbdFrame> episode() {
  std::vector<RgbdFrame> frames;
  const Eigen::Vector3d skin(225, 170, 140);
  for (int k = 0; k < 4; ++k) {
    test::SyntheticScene scene = test::table_and_case();
    if (k >= 1) {
      scene.shapes.push_back(test::make_capsule({0.115, -0.005, 0.03}, {0.115, -0.005, 0.12}, 0.02,
                                                skin, test::kHand));
    }
    if (k >= 2) {
      scene.shapes.push_back(
          test::make_capsule({-0.15, -0.2, 0.08}, {0.05, -0.22, 0.16}, 0.025, skin, test::kHand));
    }
    frames.push_back(scene.render(test::vga(320), test::front_camera(), nullptr, k / 30.0));
  }
  return frames;
}

TEST(PerceiveCli, TumSequenceGivesProblemsForOfvEstimateAndPictures) {
  const fs::path dir = fs::path(test::scratch_dir()) / "ofv_perceive_tum";
  const fs::path out = fs::path(test::scratch_dir()) / "ofv_perceive_out";
  fs::remove_all(dir);
  fs::remove_all(out);
  {
    TumSequenceWriter writer(dir.string());
    for (const RgbdFrame& f : episode()) {
      writer.write(f);
    }
  }
  const CommandRun r = run("perceive " + dir.string() + " --out " + out.string() + " --pictures");
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.err.find("4 frames, 0 lost"), std::string::npos) << r.err;
  for (int k = 0; k < 4; ++k) {
    char name[32];
    std::snprintf(name, sizeof name, "frame_%06d", k);
    ASSERT_TRUE(fs::exists(out / (std::string(name) + ".png"))) << name;
    std::ifstream in(out / (std::string(name) + ".json"));
    const auto j = nlohmann::json::parse(in);
    EXPECT_EQ(j["status"], k == 0 ? "initialised" : "tracking");
    EXPECT_GE(j["problem"]["supervoxels"].size(), 10u);
    // The frame's occluders, then those presumed beyond the image border.
    EXPECT_EQ(j["counts"]["occluders"].get<std::size_t>() + j["counts"]["beyond_view"].get<std::size_t>(),
              j["problem"]["occluders"].size());
    if (k >= 1) {
      EXPECT_GE(j["counts"]["interacting"].get<int>(), 1) << "frame " << k;
    }
    // The problem is a scene for `ofv estimate`, which gives the same t0.
    const fs::path scene = out / (std::string(name) + ".scene.json");
    std::ofstream(scene) << j["problem"].dump();
    const CommandRun e = run("estimate --compact " + scene.string());
    ASSERT_EQ(e.code, 0) << e.err;
    const auto estimate = nlohmann::json::parse(e.out);
    for (int i = 0; i < 3; ++i) {
      EXPECT_NEAR(estimate["t0"][i].get<double>(), j["estimate"]["t0"][i].get<double>(), 1e-9);
    }
  }
}

// A recording that carries ground truth (ofv's own, here made by hand from
// the synthetic scene's labels): every frame is scored, in its JSON and in
// the summary's means.
TEST(PerceiveCli, ARecordingWithLabelsIsScored) {
  const fs::path dir = fs::path(test::scratch_dir()) / "ofv_perceive_labelled";
  const fs::path out = fs::path(test::scratch_dir()) / "ofv_perceive_labelled_out";
  fs::remove_all(dir);
  fs::remove_all(out);
  {
    TumSequenceWriter writer(dir.string());
    const test::SyntheticScene scene = test::table_and_case();
    for (int k = 0; k < 3; ++k) {
      std::vector<int> labels;
      RgbdFrame f = scene.render(test::vga(320), test::front_camera(), &labels, k / 30.0);
      f.labels.resize(labels.size());
      std::transform(labels.begin(), labels.end(), f.labels.begin(), [](int label) {
        return label == test::kObject ? kPixelObject : label == test::kTable ? kPixelSupport : kPixelNone;
      });
      writer.write(f);
    }
  }
  const CommandRun r = run("perceive " + dir.string() + " --out " + out.string());
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.err.find("scores over 3 labelled frames"), std::string::npos) << r.err;
  std::ifstream in(out / "frame_000002.json");
  const auto j = nlohmann::json::parse(in);
  EXPECT_GE(j["scores"]["object_precision"].get<double>(), 0.98);
  EXPECT_GE(j["scores"]["object_recall"].get<double>(), 0.95);
  EXPECT_TRUE(j["scores"]["centroid_error_m"].is_null());  // the recording has no object centroid
  EXPECT_TRUE(j["scores"]["occluder_recall"].is_null());

  // The front end's own settings go through --set too: PCL's supervoxel
  // stage (the reference) scores as well on the same frames; a word it does
  // not know is exit 2.
  const fs::path out_ofv = fs::path(test::scratch_dir()) / "ofv_perceive_labelled_pcl";
  const CommandRun mine = run("perceive " + dir.string() + " --set supervoxels=pcl --out " + out_ofv.string());
  ASSERT_EQ(mine.code, 0) << mine.err;
  std::ifstream in_ofv(out_ofv / "frame_000002.json");
  const auto k = nlohmann::json::parse(in_ofv);
  EXPECT_GE(k["scores"]["object_precision"].get<double>(), 0.98);
  EXPECT_GE(k["scores"]["object_recall"].get<double>(), 0.95);
  EXPECT_NE(k["counts"]["supervoxels"], j["counts"]["supervoxels"]);  // another stage ran
  const CommandRun bad = run("perceive " + dir.string() + " --set supervoxels=slic");
  EXPECT_EQ(bad.code, 2);
  EXPECT_NE(bad.err.find("supervoxels"), std::string::npos) << bad.err;
}

TEST(PerceiveCli, AClosedOutputEndsTheRunCleanly) {
  // `ofv perceive REC | head -1`: the reader goes away after one line; the
  // next line fails (EPIPE, not a SIGPIPE kill) and the run ends, exit 0.
  const fs::path dir = fs::path(test::scratch_dir()) / "ofv_perceive_pipe";
  fs::remove_all(dir);
  {
    TumSequenceWriter writer(dir.string());
    const std::vector<RgbdFrame> frames = episode();
    for (int k = 0; k < 60; ++k) {
      RgbdFrame f = frames[static_cast<std::size_t>(k % 4)];
      f.timestamp = k / 30.0;
      writer.write(f);
    }
  }
  const CommandRun r = run_into_head("perceive " + dir.string());
  EXPECT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.err.find("stopped: the output's reader went away"), std::string::npos) << r.err;
}

TEST(PerceiveCli, OniRecordingStreamsJsonLines) {
  const fs::path oni = fs::path(test::scratch_dir()) / "ofv_perceive.oni";
  {
    OniWriter writer(oni.string());
    for (const RgbdFrame& f : episode()) {
      writer.write(f);
    }
  }
  const CommandRun r = run("perceive " + oni.string() + " --max-frames 3");
  ASSERT_EQ(r.code, 0) << r.err;
  std::istringstream lines(r.out);
  std::string line;
  int n = 0;
  while (std::getline(lines, line)) {
    const auto j = nlohmann::json::parse(line);
    EXPECT_EQ(j["frame"], n);
    EXPECT_NE(j["status"], "lost");
    ++n;
  }
  EXPECT_EQ(n, 3);
}

TEST(PerceiveCli, BadInputIsExitTwoWithOneLine) {
  for (const std::string& args :
       {std::string("perceive /no/such/dir"), std::string("perceive /no/such/file.oni"),
        std::string("perceive openni2://no-such-device"),
        std::string("perceive ") + test::scratch_dir() + " --box 1,2,3",
        std::string("perceive ") + test::scratch_dir() + " --pictures"}) {
    const CommandRun r = run(args);
    EXPECT_EQ(r.code, 2) << args;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << args << ": " << r.err;
    EXPECT_TRUE(r.out.empty()) << args;
  }
}

}  // namespace
}  // namespace ofv
