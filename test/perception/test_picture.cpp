// save_perception_picture: the PNG it writes, read back with OpenCV.
#include "ofv/perception/picture.h"

#include "scratch.h"
#include "synthetic_scene.h"

#include <gtest/gtest.h>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include <filesystem>
#include <stdexcept>
#include <string>

namespace fs = std::filesystem;

namespace ofv {
namespace {

/// B, G, R of an 8-bit picture pixel as R, G, B.
Eigen::Vector3i rgb_at(const cv::Mat& image, int u, int v) {
  const cv::Vec3b p = image.at<cv::Vec3b>(v, u);
  return {p[2], p[1], p[0]};
}

/// Pixels of exactly this colour outside the inset (top left, 250 x 200 at most).
int count_outside_inset(const cv::Mat& image, const Eigen::Vector3i& colour) {
  int count = 0;
  for (int v = 0; v < image.rows; ++v) {
    for (int u = v < 200 ? 250 : 0; u < image.cols; ++u) {
      count += rgb_at(image, u, v) == colour ? 1 : 0;
    }
  }
  return count;
}

TEST(PerceptionPicture, ShowsTheObjectAndInsetsTheCameraImage) {
  const RgbdFrame frame = test::table_and_case().render(test::vga(320), test::front_camera());
  perception::Perception perception{perception::PerceptionSettings{}};
  const perception::PerceptionResult r = perception.process(frame);
  ASSERT_EQ(r.status, perception::TrackingStatus::Initialised) << r.message;
  const ViewEstimate e = estimate_view(r.problem, EstimatorSettings{});
  const std::string path = test::scratch_dir() + "ofv_picture.png";
  perception::save_perception_picture(path, frame, r, e, 0.5);

  const cv::Mat image = cv::imread(path, cv::IMREAD_COLOR);
  ASSERT_FALSE(image.empty());
  EXPECT_EQ(image.cols, 800);
  EXPECT_EQ(image.rows, 600);
  // The inset: the camera image from (8, 8), scaled to 240 px wide, framed in white.
  const double s = 320.0 / 240.0;
  for (const auto& [u, v] : {std::pair{0, 0}, std::pair{239, 10}, std::pair{120, 170}}) {
    const std::size_t i = frame.index(static_cast<int>(u * s), static_cast<int>(v * s));
    const Eigen::Vector3i camera(frame.rgb[3 * i], frame.rgb[3 * i + 1], frame.rgb[3 * i + 2]);
    if (rgb_at(image, u + 8, v + 8) != Eigen::Vector3i(60, 220, 90)) {  // not a marked centroid
      EXPECT_EQ(rgb_at(image, u + 8, v + 8), camera) << "inset pixel " << u << ", " << v;
    }
  }
  EXPECT_EQ(rgb_at(image, 7, 7), Eigen::Vector3i(255, 255, 255));
  EXPECT_EQ(rgb_at(image, 799, 0), Eigen::Vector3i(24, 24, 32));  // the background
  // Object voxels (green) and the estimated tf (magenta) are drawn.
  EXPECT_GT(count_outside_inset(image, Eigen::Vector3i(60, 220, 90)), 100);
  EXPECT_GT(count_outside_inset(image, Eigen::Vector3i(255, 60, 255)), 10);
}

TEST(PerceptionPicture, LostObjectStillGivesAPicture) {
  const RgbdFrame frame = test::table_and_case().render(test::vga(160), test::front_camera());
  perception::PerceptionResult lost;
  lost.message = "no supervoxel near the object's last state";
  const std::string path = test::scratch_dir() + "ofv_picture_lost.png";
  perception::save_perception_picture(path, frame, lost, std::nullopt, 0.5);
  const cv::Mat image = cv::imread(path, cv::IMREAD_COLOR);
  ASSERT_FALSE(image.empty());
  EXPECT_EQ(image.cols, 800);
}

TEST(PerceptionPicture, UnwritablePathIsAnErrorNamingIt) {
  const RgbdFrame frame = test::table_and_case().render(test::vga(160), test::front_camera());
  const std::string path = test::scratch_dir() + "no/such/folder/picture.png";
  try {
    perception::save_perception_picture(path, frame, perception::PerceptionResult{}, std::nullopt, 0.5);
    FAIL() << "expected an error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace ofv
