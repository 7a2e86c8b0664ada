// perceive(): the front end and the estimator over a source (ofv/perception/perceive.h),
// and the record of a perceived frame (ofv/perception/perceive_files.h).
#include "ofv/perception/perceive.h"
#include "ofv/perception/perceive_files.h"

#include "ofv/io/scene_json.h"

#include "scratch.h"
#include "synthetic_scene.h"

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <vector>

namespace fs = std::filesystem;

namespace ofv {
namespace {

/// The frames of a vector, in order.
class VectorSource : public FrameSource {
 public:
  explicit VectorSource(std::vector<RgbdFrame> frames) : frames_(std::move(frames)) {}
  std::optional<RgbdFrame> next() override {
    if (next_ == frames_.size()) {
      return std::nullopt;
    }
    return frames_[next_++];
  }
  [[nodiscard]] std::string describe() const override { return "vector"; }

 private:
  std::vector<RgbdFrame> frames_;
  std::size_t next_ = 0;
};

/// The case on the table; then gone (the object is lost); then back, seen
/// from the front and from a little to the right.
std::vector<RgbdFrame> sequence() {
  test::SyntheticScene empty = test::table_and_case();
  empty.shapes.pop_back();
  const Eigen::Vector3d target(0.0, 0.0, 0.0675);
  return {test::table_and_case().render(test::vga(320), test::front_camera(), nullptr, 0.0),
          empty.render(test::vga(320), test::front_camera(), nullptr, 0.1),
          test::table_and_case().render(test::vga(320), test::front_camera(), nullptr, 0.2),
          test::table_and_case().render(
              test::vga(320), test::look_at(target + Eigen::Vector3d(0.02, -0.45, 0.22), target),
              nullptr, 0.3)};
}

std::vector<perception::PerceivedFrame> perceive_all(FrameSource& source, long max_frames,
                                         perception::PerceiveSummary* summary = nullptr) {
  std::vector<perception::PerceivedFrame> seen;
  const perception::PerceiveSummary s = perception::perceive(source, perception::PerceptionSettings{}, EstimatorSettings{}, max_frames,
                                     [&seen](const perception::PerceivedFrame& f) { seen.push_back(f); });
  if (summary != nullptr) {
    *summary = s;
  }
  return seen;
}

TEST(Perceive, AFrameThatFailsItsChecksIsSkippedAndCountedManyInARowEndTheRun) {
  std::vector<RgbdFrame> frames = sequence();
  RgbdFrame short_read = frames[0];
  short_read.depth.resize(short_read.depth.size() / 2);  // a depth image of the wrong size
  frames.insert(frames.begin() + 1, short_read);
  VectorSource source(frames);
  perception::PerceiveSummary summary;
  const auto seen = perceive_all(source, -1, &summary);
  EXPECT_EQ(seen.size(), frames.size() - 1);
  EXPECT_EQ(summary.frames, static_cast<long>(frames.size()) - 1);
  EXPECT_EQ(summary.bad_frames, 1);
  EXPECT_NE(summary.last_bad_frame.find("depth"), std::string::npos) << summary.last_bad_frame;
  // The run ends with an error naming the bound it went past.
  const auto expect_ended = [](std::vector<RgbdFrame> run, const std::string& bound) {
    VectorSource bad_run(std::move(run));
    try {
      (void)perceive_all(bad_run, -1);
      ADD_FAILURE() << bound << " went on";
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find(bound), std::string::npos) << e.what();
    }
  };
  expect_ended(std::vector<RgbdFrame>(11, short_read), "11 bad frames in a row");
  // Never two in a row, but 31 within a minute.
  std::vector<RgbdFrame> every_other;
  for (int k = 0; k < 31; ++k) {
    every_other.push_back(frames[0]);
    every_other.push_back(short_read);
  }
  expect_ended(every_other, "31 bad frames in a minute");
}

TEST(Perceive, EstimatesEachFrameWarmStartedFromTheLastView) {
  const auto frames = sequence();
  VectorSource source(frames);
  perception::PerceiveSummary summary;
  const auto seen = perceive_all(source, -1, &summary);
  ASSERT_EQ(seen.size(), frames.size());
  EXPECT_EQ(summary.frames, 4);
  EXPECT_EQ(summary.lost, 1);

  // The same front end run by hand, and the estimator on its problem with
  // the previous estimate's t_f.
  perception::Perception perception{perception::PerceptionSettings{}};
  std::optional<Eigen::Vector3d> previous_view;
  std::vector<double> front_end;
  for (std::size_t k = 0; k < frames.size(); ++k) {
    const perception::PerceivedFrame& f = seen[k];
    EXPECT_EQ(f.index, static_cast<long>(k));
    EXPECT_EQ(f.frame.timestamp, frames[k].timestamp);
    const perception::PerceptionResult r = perception.process(frames[k]);
    ASSERT_EQ(f.result.status, r.status) << "frame " << k;
    EXPECT_EQ(f.result.counts.object, r.counts.object) << "frame " << k;
    front_end.push_back(f.result.timings.total);
    if (r.status == perception::TrackingStatus::Lost) {
      EXPECT_FALSE(f.estimate) << "frame " << k;
      EXPECT_EQ(f.estimate_ms, 0.0);
      continue;
    }
    ASSERT_TRUE(f.estimate) << "frame " << k;
    EXPECT_GE(f.estimate_ms, 0.0);
    EXPECT_EQ(f.result.problem.previous_view.has_value(), previous_view.has_value())
        << "frame " << k;
    if (previous_view) {
      EXPECT_EQ(*f.result.problem.previous_view, *previous_view) << "frame " << k;
    }
    ViewProblem problem = r.problem;
    problem.previous_view = previous_view;
    const ViewEstimate e = estimate_view(problem, EstimatorSettings{});
    EXPECT_TRUE(f.estimate->tf.isApprox(e.tf, 1e-12)) << "frame " << k;
    previous_view = e.tf;
  }
  EXPECT_EQ(seen[1].result.status, perception::TrackingStatus::Lost);
  // Frame 2 starts from frame 0's view: the lost frame does not forget it.
  ASSERT_TRUE(seen[2].result.problem.previous_view);
  EXPECT_EQ(*seen[2].result.problem.previous_view, seen[0].estimate->tf);
  std::sort(front_end.begin(), front_end.end());
  EXPECT_EQ(summary.median_front_end_ms, front_end[2]);
}

TEST(Perceive, StopsAfterMaxFramesAndLeavesTheRestInTheSource) {
  VectorSource source(sequence());
  perception::PerceiveSummary summary;
  EXPECT_EQ(perceive_all(source, 2, &summary).size(), 2u);
  EXPECT_EQ(summary.frames, 2);
  EXPECT_EQ(summary.lost, 1);
  const auto rest = source.next();
  ASSERT_TRUE(rest);
  EXPECT_EQ(rest->timestamp, 0.2);

  VectorSource none(sequence());
  EXPECT_TRUE(perceive_all(none, 0, &summary).empty());
  EXPECT_EQ(summary.frames, 0);
  EXPECT_EQ(summary.median_front_end_ms, 0.0);
}

TEST(Perceive, RejectsInvalidSettingsBeforeReadingAFrame) {
  VectorSource source(sequence());
  perception::PerceptionSettings ps;
  ps.supervoxels.voxel_resolution = -1.0;
  EXPECT_THROW((void)perception::perceive(source, ps, EstimatorSettings{}, -1, nullptr), std::invalid_argument);
  EXPECT_TRUE(source.next());
}

TEST(PerceiveFiles, RecordHoldsTheEstimatorsSceneAndResult) {
  VectorSource source(sequence());
  const auto seen = perceive_all(source, -1);
  ASSERT_EQ(seen.size(), 4u);
  EstimatorParams params;
  set_param(params, "r_sphere", "0.2");

  const std::string line = perception::perceived_frame_json(seen[2], params);
  EXPECT_EQ(line.find('\n'), std::string::npos);
  const auto j = nlohmann::ordered_json::parse(line);
  std::vector<std::string> keys;
  for (const auto& item : j.items()) {
    keys.push_back(item.key());
  }
  EXPECT_EQ(keys, (std::vector<std::string>{"frame", "timestamp", "status", "problem", "estimate",
                                            "counts", "timings_ms"}));
  EXPECT_EQ(j["frame"], 2);
  EXPECT_EQ(j["timestamp"], 0.2);
  EXPECT_EQ(j["status"], "tracking");
  EXPECT_EQ(j["counts"]["object"], seen[2].result.counts.object);
  EXPECT_EQ(j["timings_ms"]["front_end"], seen[2].result.timings.total);
  EXPECT_EQ(j["timings_ms"]["estimate"], seen[2].estimate_ms);
  // `problem` is a scene for `ofv estimate`: the estimator's input and the given parameters.
  const Scene scene = scene_from_json(nlohmann::json::parse(j["problem"].dump()), "record");
  ASSERT_TRUE(scene.problem.previous_view);
  EXPECT_TRUE(scene.problem.previous_view->isApprox(seen[0].estimate->tf, 1e-12));
  EXPECT_EQ(scene.problem.positions.cols(), seen[2].result.problem.positions.cols());
  EXPECT_EQ(scene.params.resolve().r_sphere, 0.2);
  EXPECT_EQ(j["estimate"], estimate_to_json(*seen[2].estimate));

  const auto lost = nlohmann::ordered_json::parse(perception::perceived_frame_json(seen[1], params));
  EXPECT_EQ(lost["status"], "lost");
  EXPECT_TRUE(lost["problem"].is_null());
  EXPECT_TRUE(lost["estimate"].is_null());
  EXPECT_EQ(lost["message"], seen[1].result.message);
  EXPECT_EQ(lost["timings_ms"]["estimate"], 0.0);
}

TEST(PerceiveFiles, WritesTheIndentedRecordAndThePicture) {
  VectorSource source(sequence());
  const auto seen = perceive_all(source, 3);
  ASSERT_EQ(seen.size(), 3u);
  const fs::path dir = fs::path(test::scratch_dir()) / "perceive_files";
  fs::create_directories(dir);
  const EstimatorParams params;
  perception::write_perceived_frame(dir.string(), seen[2], params, true, EstimatorSettings{}.r_sphere);
  perception::write_perceived_frame(dir.string(), seen[1], params, false, EstimatorSettings{}.r_sphere);

  std::ifstream in(dir / "frame_000002.json");
  std::stringstream text;
  text << in.rdbuf();
  EXPECT_EQ(text.str(), perception::perceived_frame_json(seen[2], params, 2) + "\n");
  const cv::Mat picture = cv::imread((dir / "frame_000002.png").string());
  EXPECT_FALSE(picture.empty());
  EXPECT_TRUE(fs::exists(dir / "frame_000001.json"));
  EXPECT_FALSE(fs::exists(dir / "frame_000001.png"));

  try {
    perception::write_perceived_frame((dir / "missing").string(), seen[2], params, false, 0.2);
    FAIL() << "expected std::runtime_error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("frame_000002.json"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace ofv
