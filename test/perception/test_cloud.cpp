// Back-projection, crop and voxelisation (ofv/perception/cloud.h).
#include "ofv/perception/cloud.h"
#include "ofv/constants.h"

#include "synthetic_scene.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace ofv {
namespace {

RgbdFrame wall(double z, const Eigen::Isometry3d& wMc = Eigen::Isometry3d::Identity()) {
  RgbdFrame f;
  f.intrinsics = test::vga(320);
  f.wMc = wMc;
  f.depth.assign(static_cast<std::size_t>(320 * 240), static_cast<float>(z));
  f.rgb.assign(3 * f.depth.size(), 100);
  return f;
}

TEST(CloudBuilder, BackProjectsPixelsWithTheViSPConvention) {
  RgbdFrame f = wall(1.0);
  Eigen::Isometry3d wMc = Eigen::Isometry3d::Identity();
  wMc.translation() = Eigen::Vector3d(1.0, 2.0, 3.0);
  f.wMc = wMc;
  perception::CloudSettings s;
  s.pixel_stride = 1;
  s.voxel_resolution = 0.0;  // every point
  perception::CloudBuilder builder(s);
  perception::WorldCloud cloud;
  builder.build(f, perception::CropVolume{}, cloud);
  ASSERT_EQ(cloud.points.size(), f.depth.size());
  // Pixel (u, v) = (0, 0): X = (0 - cx) Z / fx, left and up (negative) of the axis.
  const CameraIntrinsics& k = f.intrinsics;
  EXPECT_NEAR(cloud.points[0].x(), 1.0 - k.cx / k.fx, 1e-5);
  EXPECT_NEAR(cloud.points[0].y(), 2.0 - k.cy / k.fy, 1e-5);
  EXPECT_NEAR(cloud.points[0].z(), 4.0, 1e-5);
  const std::size_t last = f.index(319, 239);
  EXPECT_NEAR(cloud.points[last].x(), 1.0 + (319 - k.cx) / k.fx, 1e-5);
  EXPECT_NEAR(cloud.points[last].y(), 2.0 + (239 - k.cy) / k.fy, 1e-5);
}

TEST(CloudBuilder, DropsZeroAndNanDepth) {
  RgbdFrame f = wall(0.8);
  f.depth[0] = 0.0f;
  f.depth[1] = std::numeric_limits<float>::quiet_NaN();
  f.depth[2] = -1.0f;
  f.depth[3] = std::numeric_limits<float>::infinity();
  perception::CloudSettings s;
  s.pixel_stride = 1;
  s.voxel_resolution = 0.0;
  perception::CloudBuilder builder(s);
  perception::WorldCloud cloud;
  builder.build(f, perception::CropVolume{}, cloud);
  EXPECT_EQ(cloud.points.size(), f.depth.size() - 4);
  EXPECT_EQ(cloud.valid_pixels, f.depth.size() - 4);
  for (const auto& p : cloud.points) {
    ASSERT_TRUE(p.allFinite());
  }
}

TEST(CloudBuilder, CropsToSphereBoxAndDepth) {
  const RgbdFrame f = wall(1.0);
  perception::CloudSettings s;
  s.pixel_stride = 1;
  s.voxel_resolution = 0.0;
  perception::CloudBuilder builder(s);
  perception::WorldCloud cloud;
  perception::CropVolume sphere;
  sphere.centre = Eigen::Vector3d(0.0, 0.0, 1.0);
  sphere.radius = 0.1;
  builder.build(f, sphere, cloud);
  ASSERT_FALSE(cloud.points.empty());
  for (const auto& p : cloud.points) {
    ASSERT_LE((p.cast<double>() - sphere.centre).norm(), 0.1 + 1e-6);
  }
  // Disc of radius 0.1 m on the wall at 1 m: pi (0.1 fx)^2 pixels.
  const double expected = kPi * std::pow(0.1 * f.intrinsics.fx, 2);
  EXPECT_NEAR(static_cast<double>(cloud.points.size()), expected, 0.03 * expected);

  perception::CropVolume box;
  box.box = Eigen::AlignedBox3d(Eigen::Vector3d(0.0, 0.0, 0.5), Eigen::Vector3d(0.2, 0.1, 1.5));
  builder.build(f, box, cloud);
  ASSERT_FALSE(cloud.points.empty());
  for (const auto& p : cloud.points) {
    ASSERT_TRUE(box.box.contains(p.cast<double>()));
  }
  perception::CropVolume near;
  near.max_depth = 0.9;
  builder.build(f, near, cloud);
  EXPECT_TRUE(cloud.points.empty());
  EXPECT_EQ(cloud.valid_pixels, f.depth.size());
}

TEST(CloudBuilder, VoxelisesToOnePointPerOccupiedVoxel) {
  const RgbdFrame f = wall(0.5);
  perception::CloudSettings s;
  s.pixel_stride = 1;
  s.voxel_resolution = 0.01;
  perception::CloudBuilder builder(s);
  perception::WorldCloud cloud;
  builder.build(f, perception::CropVolume{}, cloud);
  // The wall spans 320/fx*0.5 x 240/fy*0.5 m at 1 cm voxels.
  const double w = 320.0 / f.intrinsics.fx * 0.5 / 0.01;
  const double h = 240.0 / f.intrinsics.fy * 0.5 / 0.01;
  EXPECT_NEAR(static_cast<double>(cloud.points.size()), (w + 1) * (h + 1), 0.1 * w * h);
  for (std::size_t i = 0; i < cloud.points.size(); ++i) {
    EXPECT_NEAR(cloud.points[i].z(), 0.5f, 1e-5f);
    EXPECT_NEAR(cloud.colours[i].x(), 100.0f, 1e-3f);
  }
  // Reuse: the same frame twice gives the same cloud.
  perception::WorldCloud again;
  builder.build(f, perception::CropVolume{}, again);
  EXPECT_EQ(again.points.size(), cloud.points.size());
}

TEST(CloudBuilder, RejectsBuffersThatDisagreeWithTheIntrinsics) {
  RgbdFrame f = wall(1.0);
  f.depth.pop_back();
  perception::CloudBuilder builder;
  perception::WorldCloud cloud;
  EXPECT_THROW(builder.build(f, perception::CropVolume{}, cloud), std::invalid_argument);
  f = wall(1.0);
  f.rgb.resize(5);
  EXPECT_THROW(builder.build(f, perception::CropVolume{}, cloud), std::invalid_argument);
  perception::CloudSettings bad;
  bad.pixel_stride = 0;
  EXPECT_THROW(perception::CloudBuilder{bad}, std::invalid_argument);
}

}  // namespace
}  // namespace ofv
