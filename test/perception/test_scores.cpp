// Perception scores (ofv/perception/scores.h) on hand-made labelled frames
// whose answers are counted by hand: a 40 x 30 wall at 0.5 m seen with a
// 40 px focal length, so that each pixel (12.5 mm at that depth) is a cell
// of its own at the 8 mm voxels.
#include "ofv/perception/scores.h"

#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

namespace ofv {
namespace {

constexpr int kWidth = 40;
constexpr int kHeight = 30;
constexpr double kDepth = 0.5;

// Columns [0, 10): support; [10, 20): object; [20, 30): occluder 0;
// [30, 40): the holder. Row 0 shows nothing.
RgbdFrame labelled_wall() {
  RgbdFrame f;
  f.intrinsics = CameraIntrinsics{kWidth, kHeight, 40.0, 40.0, 20.0, 15.0};
  f.depth.assign(static_cast<std::size_t>(kWidth * kHeight), static_cast<float>(kDepth));
  f.labels.resize(f.depth.size());
  for (int v = 0; v < kHeight; ++v) {
    for (int u = 0; u < kWidth; ++u) {
      const PixelLabel label = u < 10 ? kPixelSupport : u < 20 ? kPixelObject : u < 30 ? kPixelOccluder0 : kPixelInteracting;
      f.labels[f.index(u, v)] = v == 0 ? kPixelNone : label;
      if (v == 0) f.depth[f.index(u, v)] = 0.0f;
    }
  }
  return f;
}

Eigen::Vector3f point(const RgbdFrame& f, int u, int v) {
  const CameraIntrinsics& k = f.intrinsics;
  return Eigen::Vector3f(static_cast<float>((u - k.cx) / k.fx * kDepth), static_cast<float>((v - k.cy) / k.fy * kDepth),
                         static_cast<float>(kDepth));
}

perception::PerceptionSettings every_pixel() {
  perception::PerceptionSettings s;
  s.cloud.pixel_stride = 1;
  return s;
}

// A result with one supervoxel per class; `cls(u)` gives each column's class.
template <typename ClassOf>
perception::PerceptionResult result_of(const RgbdFrame& f, ClassOf cls) {
  perception::PerceptionResult r;
  r.status = perception::TrackingStatus::Tracking;
  for (const perception::SupervoxelClass c : {perception::SupervoxelClass::Object, perception::SupervoxelClass::Interacting, perception::SupervoxelClass::Occluder,
                                  perception::SupervoxelClass::Background}) {
    perception::SupervoxelInfo s;
    s.label = c;
    r.supervoxels.push_back(s);
  }
  for (int v = 1; v < kHeight; ++v) {
    for (int u = 0; u < kWidth; ++u) {
      r.voxels.push_back(point(f, u, v));
      r.voxel_owner.push_back(static_cast<int>(cls(u)));
    }
  }
  return r;
}

perception::PerceptionTruth truth_at(const Eigen::Vector3d& centroid, double r_sphere = 1.0) {
  perception::PerceptionTruth t;
  t.centroid = centroid;
  t.r_sphere = r_sphere;
  return t;
}

perception::SupervoxelClass perfect(int u) {
  return u >= 10 && u < 20 ? perception::SupervoxelClass::Object : u >= 20 && u < 30 ? perception::SupervoxelClass::Occluder
                                                                          : perception::SupervoxelClass::Background;
}

TEST(VoxelLabels, EachCellTakesTheLabelMostOfItsPixelsShow) {
  RgbdFrame f = labelled_wall();
  // 12.5 mm pixels in 2.5 cm cells: about two by two pixels per cell.
  const perception::VoxelLabels cells(f, 0.025, 1, 3.0);
  for (const perception::VoxelLabels::Cell& c : cells.cells()) EXPECT_NE(c.label, kPixelNone);  // row 0 has no depth
  EXPECT_EQ(cells.label_at(point(f, 15, 15)), kPixelObject);
  EXPECT_EQ(cells.label_at(point(f, 25, 15)), kPixelOccluder0);
  // Three object pixels against one occluder pixel: object.
  f.labels[f.index(14, 14)] = kPixelOccluder0;
  const perception::VoxelLabels changed(f, 0.025, 1, 3.0);
  EXPECT_EQ(changed.label_at(point(f, 14, 14)), kPixelObject);
  // Far from any pixel: nothing.
  EXPECT_EQ(cells.label_at(Eigen::Vector3f(0.0f, 0.0f, 2.0f)), kPixelNone);
  EXPECT_EQ(cells.find(Eigen::Vector3f(0.0f, 0.0f, 2.0f)), -1);
}

TEST(VoxelLabels, RefusesAFrameWithoutLabelsOrBadArguments) {
  RgbdFrame f = labelled_wall();
  EXPECT_THROW(perception::VoxelLabels(f, 0.0, 1, 3.0), std::invalid_argument);
  EXPECT_THROW(perception::VoxelLabels(f, 0.008, 0, 3.0), std::invalid_argument);
  f.labels.resize(3);
  EXPECT_THROW(perception::VoxelLabels(f, 0.008, 1, 3.0), std::invalid_argument);
  f.labels.clear();
  EXPECT_THROW(perception::VoxelLabels(f, 0.008, 1, 3.0), std::invalid_argument);
}

TEST(PerceptionScores, APerfectResultScoresOne) {
  const RgbdFrame f = labelled_wall();
  perception::PerceptionResult r = result_of(f, perfect);
  r.centroid = Eigen::Vector3d(0.03, 0.04, 0.5);
  const perception::PerceptionScores s = perception::score_perception(f, r, truth_at(Eigen::Vector3d(0.0, 0.0, 0.5)), every_pixel());
  EXPECT_EQ(s.object_cells, 10u * 29u);
  EXPECT_EQ(s.occluder_cells, 10u * 29u);
  EXPECT_DOUBLE_EQ(*s.object_precision, 1.0);
  EXPECT_DOUBLE_EQ(*s.object_recall, 1.0);
  EXPECT_DOUBLE_EQ(*s.occluder_precision, 1.0);
  EXPECT_DOUBLE_EQ(*s.occluder_recall, 1.0);
  EXPECT_NEAR(*s.centroid_error, 0.05, 1e-12);
  EXPECT_FALSE(s.hidden_error);  // nothing hidden
}

TEST(PerceptionScores, CountsTheVoxelsGivenToTheWrongClass) {
  const RgbdFrame f = labelled_wall();
  // Object columns 18, 19 called occluder; the holder's columns 30-34 called
  // occluder; occluder column 20 called object; the support called occluder
  // (the paper's rule: left out of the occluder scores).
  const perception::PerceptionResult r = result_of(f, [](int u) {
    if (u < 10) return perception::SupervoxelClass::Occluder;
    if (u == 18 || u == 19) return perception::SupervoxelClass::Occluder;
    if (u == 20) return perception::SupervoxelClass::Object;
    if (u >= 30 && u < 35) return perception::SupervoxelClass::Occluder;
    return perfect(u);
  });
  const perception::PerceptionScores s = perception::score_perception(f, r, truth_at(Eigen::Vector3d(0.0, 0.0, 0.5)), every_pixel());
  // Object: columns 10-17 right, 20 wrong: 8 of 9; found 8 of 10 columns.
  EXPECT_NEAR(*s.object_precision, 8.0 / 9.0, 1e-12);
  // Recall finds a cell within one voxel edge of an object voxel: pixels are
  // 12.5 mm apart, farther than the 8 mm edge, so no neighbour counts.
  EXPECT_NEAR(*s.object_recall, 8.0 / 10.0, 1e-12);
  // Occluder: columns 21-29 right; 18, 19 (object) and 30-34 (holder) wrong.
  EXPECT_NEAR(*s.occluder_precision, 9.0 / 16.0, 1e-12);
  EXPECT_NEAR(*s.occluder_recall, 9.0 / 10.0, 1e-12);
}

TEST(PerceptionScores, OccluderRecallCountsOnlyTheSphere) {
  const RgbdFrame f = labelled_wall();
  // Only the occluder's columns 20-23 are called occluder.
  const perception::PerceptionResult r = result_of(f, [](int u) {
    return u >= 24 && u < 30 ? perception::SupervoxelClass::Background : perfect(u);
  });
  // A sphere around column 21's centre (x = 0.0125 m) reaching columns 20-22 only (< 2 px).
  const Eigen::Vector3d centre(point(f, 21, 15).cast<double>());
  const perception::PerceptionScores s = perception::score_perception(f, r, truth_at(centre, 0.02), every_pixel());
  // In the sphere: columns 20-22 of rows 14-16 (+-1 px, 12.5 mm < 20 mm) plus
  // the 4 diagonal ones out (17.7 mm < 20 mm: in): a 3 x 3 block.
  EXPECT_EQ(s.occluder_cells, 9u);
  EXPECT_DOUBLE_EQ(*s.occluder_recall, 1.0);
  EXPECT_DOUBLE_EQ(*s.occluder_precision, 1.0);
}

TEST(PerceptionScores, ALostObjectHasNoPrecisionAndNoRecall) {
  const RgbdFrame f = labelled_wall();
  perception::PerceptionResult r = result_of(f, perfect);
  r.status = perception::TrackingStatus::Lost;
  const perception::PerceptionScores s = perception::score_perception(f, r, truth_at(Eigen::Vector3d(0.0, 0.0, 0.5)), every_pixel());
  EXPECT_FALSE(s.object_precision);
  EXPECT_DOUBLE_EQ(*s.object_recall, 0.0);
  EXPECT_FALSE(s.centroid_error);
}

TEST(PerceptionScores, NoOccluderInTheSphereGivesNoOccluderRecall) {
  RgbdFrame f = labelled_wall();
  for (std::uint16_t& label : f.labels) label = label == kPixelOccluder0 ? std::uint16_t{kPixelSupport} : label;
  const perception::PerceptionResult r = result_of(f, [](int u) { return u >= 10 && u < 20 ? perception::SupervoxelClass::Object : perception::SupervoxelClass::Background; });
  const perception::PerceptionScores s = perception::score_perception(f, r, truth_at(Eigen::Vector3d(0.0, 0.0, 0.5)), every_pixel());
  EXPECT_EQ(s.occluder_cells, 0u);
  EXPECT_FALSE(s.occluder_recall);
  EXPECT_FALSE(s.occluder_precision);  // nothing called occluder
}

TEST(PerceptionScores, WithoutTheTrueCentroidThereIsNoOccluderRecallNorCentroidError) {
  const RgbdFrame f = labelled_wall();
  const perception::PerceptionResult r = result_of(f, perfect);
  const perception::PerceptionScores s = perception::score_perception(f, r, perception::PerceptionTruth{}, every_pixel());
  EXPECT_DOUBLE_EQ(*s.object_precision, 1.0);
  EXPECT_DOUBLE_EQ(*s.object_recall, 1.0);
  EXPECT_DOUBLE_EQ(*s.occluder_precision, 1.0);
  EXPECT_FALSE(s.occluder_recall);
  EXPECT_FALSE(s.centroid_error);
}

TEST(PerceptionScores, HiddenErrorIsTheDistanceToTheTrueSurface) {
  const RgbdFrame f = labelled_wall();
  perception::PerceptionResult r = result_of(f, perfect);
  perception::PerceptionTruth t = truth_at(Eigen::Vector3d(0.0, 0.0, 0.5));
  // The true surface: a plane z = 0.6 sampled every 2 mm; hidden voxels 1 and 3 cm in front of it.
  for (int i = -50; i <= 50; ++i) {
    for (int j = -50; j <= 50; ++j) t.surface.emplace_back(0.002 * i, 0.002 * j, 0.6);
  }
  r.hidden = {Eigen::Vector3f(0.01f, 0.02f, 0.59f), Eigen::Vector3f(-0.03f, 0.0f, 0.57f)};
  const perception::PerceptionScores s = perception::score_perception(f, r, t, every_pixel());
  EXPECT_EQ(s.hidden_voxels, 2u);
  EXPECT_NEAR(*s.hidden_error, 0.02, 1e-6);
}

TEST(PerceptionScores, IsTheSameFromAnyCameraPose) {
  // The camera, the wall and the result moved and turned together: the
  // cells are world-aligned, so others share pixels, but a perfect result
  // still scores 1.
  RgbdFrame f = labelled_wall();
  f.wMc = Eigen::Translation3d(0.3, -0.2, 1.0) * Eigen::AngleAxisd(0.7, Eigen::Vector3d(0.2, 1.0, 0.3).normalized());
  perception::PerceptionResult r = result_of(f, perfect);
  for (Eigen::Vector3f& p : r.voxels) p = (f.wMc.cast<float>() * p);
  const Eigen::Vector3d centre = f.wMc * Eigen::Vector3d(0.0, 0.0, 0.5);
  const perception::PerceptionScores s = perception::score_perception(f, r, truth_at(centre), every_pixel());
  EXPECT_DOUBLE_EQ(*s.object_precision, 1.0);
  EXPECT_DOUBLE_EQ(*s.object_recall, 1.0);
  EXPECT_DOUBLE_EQ(*s.occluder_precision, 1.0);
  EXPECT_DOUBLE_EQ(*s.occluder_recall, 1.0);
}

}  // namespace
}  // namespace ofv
