// ofv's supervoxel stage (src/perception/vccs.h) on hand-made clouds with
// known answers, and against PCL's on a rendered frame.
#include "../../src/perception/point_grid.h"
#include "../../src/perception/vccs.h"

#include "ofv/perception/cloud.h"

#include "synthetic_scene.h"

#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <chrono>
#include <array>
#include <map>
#include <numeric>
#include <random>
#include <set>
#include <tuple>

namespace ofv {
namespace {

using perception::SupervoxelSettings;
using perception::WorldCloud;
using perception::detail::SupervoxelOutput;

const Eigen::Vector3d kCamera(0.0, -0.5, 0.4);

/// A cloud on the voxel grid: one point per 8 mm cell of the surface.
struct CloudMaker {
  WorldCloud cloud;
  std::vector<int> label;  // per point
  void add(const Eigen::Vector3f& p, const Eigen::Vector3f& colour, int l) {
    cloud.points.push_back(p);
    cloud.colours.push_back(colour);
    label.push_back(l);
  }
  /// A rectangle p0 + s u + t v, s in [0, a], t in [0, b], sampled at `step`.
  void rectangle(const Eigen::Vector3f& p0, const Eigen::Vector3f& u, const Eigen::Vector3f& v, float a, float b,
                 float step, const Eigen::Vector3f& colour, int l) {
    for (float s = 0.5f * step; s < a; s += step) {
      for (float t = 0.5f * step; t < b; t += step) add(p0 + s * u + t * v, colour, l);
    }
  }
};

/// The cloud through the front end's own voxelisation (as the pipeline gives it).
WorldCloud voxelised(const WorldCloud& raw, double voxel) {
  WorldCloud out;
  std::map<std::tuple<int, int, int>, std::pair<Eigen::Vector3f, Eigen::Vector3f>> sums;
  std::map<std::tuple<int, int, int>, int> counts;
  for (std::size_t i = 0; i < raw.points.size(); ++i) {
    const Eigen::Vector3i c = (raw.points[i] / static_cast<float>(voxel)).array().floor().cast<int>();
    const auto key = std::make_tuple(c.x(), c.y(), c.z());
    auto& s = sums[key];
    if (counts[key]++ == 0) s = {Eigen::Vector3f::Zero(), Eigen::Vector3f::Zero()};
    s.first += raw.points[i];
    s.second += raw.colours[i];
  }
  for (const auto& [key, s] : sums) {
    const float n = static_cast<float>(counts[key]);
    out.points.push_back(s.first / n);
    out.colours.push_back(s.second / n);
  }
  return out;
}

SupervoxelOutput run(const WorldCloud& cloud, const SupervoxelSettings& settings = {}) {
  SupervoxelOutput out;
  perception::detail::vccs_supervoxels(cloud, settings, kCamera, out);
  return out;
}

void expect_consistent(const SupervoxelOutput& out) {
  ASSERT_EQ(out.voxels.size(), out.owner.size());
  ASSERT_EQ(out.voxels.size(), out.colours.size());
  std::vector<int> count(out.supervoxels.size(), 0);
  for (const int o : out.owner) {
    ASSERT_GE(o, 0);
    ASSERT_LT(o, static_cast<int>(out.supervoxels.size()));
    ++count[static_cast<std::size_t>(o)];
  }
  for (std::size_t s = 0; s < out.supervoxels.size(); ++s) {
    const perception::SupervoxelInfo& info = out.supervoxels[s];
    EXPECT_EQ(info.voxel_count, count[s]);
    EXPECT_GT(info.voxel_count, 0);
    EXPECT_TRUE(info.centroid.allFinite());
    EXPECT_NEAR(info.normal.norm(), 1.0, 1e-9);
    EXPECT_GE(info.normal.dot(kCamera - info.centroid), 0.0) << "normal faces the camera";
  }
  for (const auto& [a, b] : out.touching) {
    EXPECT_LT(a, b);
    EXPECT_LT(b, static_cast<int>(out.supervoxels.size()));
  }
}

TEST(Vccs, AnEmptyCloudGivesNothing) {
  const SupervoxelOutput out = run(WorldCloud{});
  EXPECT_TRUE(out.supervoxels.empty());
  EXPECT_TRUE(out.voxels.empty());
}

TEST(Vccs, APlaneIsCutIntoPatchesOfAboutTheSeedSizeWithItsNormal) {
  CloudMaker m;
  const Eigen::Vector3f grey(128, 128, 128);
  m.rectangle({-0.1f, -0.1f, 0.0f}, Eigen::Vector3f::UnitX(), Eigen::Vector3f::UnitY(), 0.2f, 0.2f, 0.004f, grey, 1);
  const SupervoxelOutput out = run(voxelised(m.cloud, 0.008));
  expect_consistent(out);
  // 0.2 m x 0.2 m in cells of R_seed = 0.02 m: about 100 supervoxels.
  EXPECT_GE(out.supervoxels.size(), 80u);
  EXPECT_LE(out.supervoxels.size(), 130u);
  for (const auto& s : out.supervoxels) {
    EXPECT_TRUE(s.normal_valid);
    EXPECT_GT(s.normal.z(), 0.999) << s.normal.transpose();
    EXPECT_NEAR(s.centroid.z(), 0.0, 1e-6);
  }
  // Every voxel of a connected plane is reached.
  EXPECT_EQ(out.voxels.size(), voxelised(m.cloud, 0.008).points.size());
  EXPECT_FALSE(out.touching.empty());
}

TEST(Vccs, ASurfaceAlongACellFaceIsOneLayerOfVoxels) {
  // A plane on the cell face z = 0.016 whose points lie 0.5 mm either side of
  // it (as a sensor's noise puts them) fills two cells per column; it must
  // give what the same plane inside a cell gives: one voxel per column, on
  // the plane, so that no part of it counts twice.
  const Eigen::Vector3f grey(128, 128, 128);
  CloudMaker inside, split;
  inside.rectangle({-0.1f, -0.1f, 0.012f}, Eigen::Vector3f::UnitX(), Eigen::Vector3f::UnitY(), 0.2f, 0.2f, 0.002f, grey, 1);
  for (const float side : {-0.0005f, 0.0005f}) {
    split.rectangle({-0.1f, -0.1f, 0.016f + side}, Eigen::Vector3f::UnitX(), Eigen::Vector3f::UnitY(), 0.2f, 0.2f, 0.002f,
                    grey, 1);
  }
  const WorldCloud cloud = voxelised(split.cloud, 0.008);
  ASSERT_EQ(cloud.points.size(), 2 * voxelised(inside.cloud, 0.008).points.size());
  const SupervoxelOutput one = run(voxelised(inside.cloud, 0.008));
  const SupervoxelOutput out = run(cloud);
  expect_consistent(out);
  EXPECT_EQ(out.voxels.size(), one.voxels.size());
  for (const Eigen::Vector3f& v : out.voxels) EXPECT_NEAR(v.z(), 0.016f, 1e-4f);
  EXPECT_NEAR(static_cast<double>(out.supervoxels.size()), static_cast<double>(one.supervoxels.size()), 10.0);
  // A surface across the grid (a wall along z) keeps a voxel per cell: its
  // face neighbours' means are a voxel apart; so does one at 45 degrees
  // (halves of a column half a voxel apart).
  CloudMaker wall, slope;
  wall.rectangle({-0.1f, 0.0f, 0.0f}, Eigen::Vector3f::UnitX(), Eigen::Vector3f::UnitZ(), 0.2f, 0.12f, 0.002f, grey, 1);
  slope.rectangle({-0.1f, 0.0f, 0.0f}, Eigen::Vector3f::UnitX(), Eigen::Vector3f(0.0f, 1.0f, 1.0f).normalized(), 0.2f,
                  0.12f, 0.002f, grey, 1);
  for (const CloudMaker* m : {&wall, &slope}) {
    const WorldCloud c = voxelised(m->cloud, 0.008);
    EXPECT_EQ(run(c).voxels.size(), c.points.size());
  }
}

TEST(Vccs, TwoPlanesMeetingAtAnEdgeAreCutAlongTheEdge) {
  // A floor (z = 0, y > 0) and a wall (y = 0, z > 0), seen from the camera at -y, +z.
  CloudMaker m;
  const Eigen::Vector3f grey(128, 128, 128);
  m.rectangle({-0.1f, 0.0f, 0.0f}, Eigen::Vector3f::UnitX(), Eigen::Vector3f::UnitY(), 0.2f, 0.12f, 0.004f, grey, 1);
  m.rectangle({-0.1f, 0.0f, 0.0f}, Eigen::Vector3f::UnitX(), Eigen::Vector3f::UnitZ(), 0.2f, 0.12f, 0.004f, grey, 2);
  const SupervoxelOutput out = run(voxelised(m.cloud, 0.008));
  expect_consistent(out);
  // A voxel is on the floor or the wall; the one row of voxels along the edge is on both.
  const auto plane_of = [](const Eigen::Vector3f& p) { return p.z() < 0.008f && p.y() < 0.008f ? 0 : p.z() < p.y() ? 1 : 2; };
  std::vector<std::array<int, 3>> counts(out.supervoxels.size(), {0, 0, 0});
  for (std::size_t i = 0; i < out.voxels.size(); ++i) ++counts[static_cast<std::size_t>(out.owner[i])][static_cast<std::size_t>(plane_of(out.voxels[i]))];
  int floor = 0, wall = 0, across = 0;
  for (std::size_t s = 0; s < out.supervoxels.size(); ++s) {
    const auto& [edge, on_floor, on_wall] = counts[s];
    const auto& info = out.supervoxels[s];
    if (on_floor > 0 && on_wall > 0) {
      ++across;
      continue;
    }
    if (on_floor > 0) {
      ++floor;
      if (edge == 0) {
        EXPECT_GT(info.normal.z(), 0.97) << info.normal.transpose();  // voxels near the edge see both planes
      }
    } else if (on_wall > 0) {
      ++wall;
      if (edge == 0) {
        EXPECT_LT(info.normal.y(), -0.97) << info.normal.transpose();
      }
    }
  }
  // 0.2 m x 0.12 m a plane: about 60 cells of R_seed each; only supervoxels
  // seeded at the edge may reach over it (at most one per seed cell along it).
  EXPECT_GE(floor, 40);
  EXPECT_GE(wall, 40);
  EXPECT_LE(across, 10) << "supervoxels with voxels on both planes beyond the edge row";
}

TEST(Vccs, TwoTouchingBoxesOfDifferentColoursShareNoSupervoxel) {
  // Two cubes side by side on their common face x = 0, both seen from the
  // front (-y): the front faces form one plane, cut only by colour.
  CloudMaker m;
  const Eigen::Vector3f red(200, 40, 40), blue(40, 40, 200);
  m.rectangle({-0.1f, 0.0f, 0.0f}, Eigen::Vector3f::UnitX(), Eigen::Vector3f::UnitZ(), 0.1f, 0.1f, 0.004f, red, 1);
  m.rectangle({0.0f, 0.0f, 0.0f}, Eigen::Vector3f::UnitX(), Eigen::Vector3f::UnitZ(), 0.1f, 0.1f, 0.004f, blue, 2);
  SupervoxelSettings settings;
  settings.colour_importance = 1.0;  // colour decides on a plane
  const SupervoxelOutput out = run(voxelised(m.cloud, 0.008), settings);
  expect_consistent(out);
  for (std::size_t s = 0; s < out.supervoxels.size(); ++s) {
    int red_voxels = 0, blue_voxels = 0;
    for (std::size_t i = 0; i < out.voxels.size(); ++i) {
      if (out.owner[i] != static_cast<int>(s)) continue;
      // Voxels straddling x = 0 average both colours: count them by x.
      if (std::abs(out.voxels[i].x()) < 0.004f) continue;
      (out.voxels[i].x() < 0.0f ? red_voxels : blue_voxels) += 1;
    }
    EXPECT_TRUE(red_voxels == 0 || blue_voxels == 0)
        << "supervoxel " << s << ": " << red_voxels << " red and " << blue_voxels << " blue voxels";
  }
}

/// The cloud and the supervoxels of a frame are the same bit for bit on
/// one thread and on all (the stage's loops run on oneTBB), and from a
/// Vccs that kept its buffers from another frame.
TEST(Vccs, TheSameFrameGivesTheSameSupervoxelsWhateverTheThreadsAndTheFramesBefore) {
  test::SyntheticScene scene = test::table_and_case();
  scene.shapes.push_back(test::make_capsule({0.115, -0.005, 0.03}, {0.115, -0.005, 0.12}, 0.02,
                                            Eigen::Vector3d(225, 170, 140), test::kHand));
  const RgbdFrame frame = scene.render(test::vga(640), test::front_camera());
  const auto cloud_of = [&](const RgbdFrame& f) {
    perception::CloudBuilder builder(perception::CloudSettings{});
    WorldCloud cloud;
    builder.build(f, {}, cloud);
    return cloud;
  };
  tbb::task_arena one_thread(1);
  WorldCloud alone;
  one_thread.execute([&] { alone = cloud_of(frame); });
  const WorldCloud cloud = cloud_of(frame);
  ASSERT_GT(cloud.points.size(), 4000u);
  EXPECT_EQ(cloud.points, alone.points);
  EXPECT_EQ(cloud.colours, alone.colours);
  EXPECT_EQ(cloud.cropped_points, alone.cropped_points);

  SupervoxelOutput a, b;
  one_thread.execute([&] { perception::detail::vccs_supervoxels(cloud, {}, kCamera, a); });
  perception::detail::Vccs reused;
  reused.run(cloud_of(test::table_and_case().render(test::vga(320), test::front_camera())), {}, kCamera, b);
  reused.run(cloud, {}, kCamera, b);
  ASSERT_GT(a.supervoxels.size(), 100u);
  ASSERT_EQ(a.supervoxels.size(), b.supervoxels.size());
  for (std::size_t s = 0; s < a.supervoxels.size(); ++s) {
    EXPECT_EQ(a.supervoxels[s].centroid, b.supervoxels[s].centroid);
    EXPECT_EQ(a.supervoxels[s].normal, b.supervoxels[s].normal);
    EXPECT_EQ(a.supervoxels[s].voxel_count, b.supervoxels[s].voxel_count);
  }
  EXPECT_EQ(a.voxels, b.voxels);
  EXPECT_EQ(a.owner, b.owner);
  EXPECT_EQ(a.touching, b.touching);
}

TEST(Vccs, HolesAndMissingDepthLeaveSeparatePiecesAndNoCrash) {
  // A frame whose depth has a band of NaN and a band of zeros across it.
  const test::SyntheticScene scene = test::table_and_case();
  RgbdFrame frame = scene.render(test::vga(320), test::front_camera());
  for (int v = 100; v < 120; ++v) {
    for (int u = 0; u < frame.intrinsics.width; ++u) {
      frame.depth[frame.index(u, v)] = v < 110 ? std::numeric_limits<float>::quiet_NaN() : 0.0f;
    }
  }
  perception::CloudBuilder builder(perception::CloudSettings{});
  WorldCloud cloud;
  builder.build(frame, {}, cloud);
  const SupervoxelOutput out = run(cloud);
  expect_consistent(out);
  EXPECT_GT(out.supervoxels.size(), 100u);
  // A lone voxel far from everything seeds nothing (fewer voxels around it than a twentieth of a disc).
  WorldCloud speck = cloud;
  speck.points.emplace_back(5.0f, 5.0f, 5.0f);
  speck.colours.emplace_back(10.0f, 10.0f, 10.0f);
  SupervoxelSettings coarse;
  coarse.seed_resolution = 0.1;  // min count 0.05 pi 0.05^2 / 0.008^2 = 6.1 voxels
  const SupervoxelOutput with_speck = run(speck, coarse);
  for (const Eigen::Vector3f& p : with_speck.voxels) EXPECT_LT(p.norm(), 4.0f);
}

}  // namespace
}  // namespace ofv

namespace ofv {
namespace {

/// Segmentation measures of a supervoxel output against a frame's labels:
/// the under-segmentation error (the fraction of voxels outside their
/// supervoxel's majority label) and the boundary recall (the fraction of
/// voxels with a 26-neighbour of another label that also have one in
/// another supervoxel).
struct Segmentation {
  double undersegmentation = 0.0;
  double boundary_recall = 0.0;
  std::size_t supervoxels = 0;
};

Segmentation measure(const SupervoxelOutput& out, const RgbdFrame& frame, const std::vector<int>& labels, double voxel) {
  const Eigen::Isometry3d cMw = frame.wMc.inverse();
  std::vector<int> label(out.voxels.size(), -1);
  std::map<std::tuple<int, int, int>, std::size_t> cell;
  for (std::size_t i = 0; i < out.voxels.size(); ++i) {
    const Eigen::Vector3d pc = cMw * out.voxels[i].cast<double>();
    const int u = static_cast<int>(std::lround(frame.intrinsics.fx * pc.x() / pc.z() + frame.intrinsics.cx));
    const int v = static_cast<int>(std::lround(frame.intrinsics.fy * pc.y() / pc.z() + frame.intrinsics.cy));
    if (u >= 0 && v >= 0 && u < frame.intrinsics.width && v < frame.intrinsics.height) label[i] = labels[frame.index(u, v)];
    const Eigen::Vector3i c = (out.voxels[i] / static_cast<float>(voxel)).array().floor().cast<int>();
    cell[{c.x(), c.y(), c.z()}] = i;
  }
  std::vector<std::map<int, int>> votes(out.supervoxels.size());
  for (std::size_t i = 0; i < out.voxels.size(); ++i) ++votes[static_cast<std::size_t>(out.owner[i])][label[i]];
  std::size_t outside = 0;
  for (const auto& v : votes) {
    int sum = 0, most = 0;
    for (const auto& [l, count] : v) {
      sum += count;
      most = std::max(most, count);
    }
    outside += static_cast<std::size_t>(sum - most);
  }
  std::size_t boundary = 0, recalled = 0;
  for (std::size_t i = 0; i < out.voxels.size(); ++i) {
    const Eigen::Vector3i c = (out.voxels[i] / static_cast<float>(voxel)).array().floor().cast<int>();
    bool on_boundary = false, cut = false;
    for (int dz = -1; dz <= 1; ++dz) {
      for (int dy = -1; dy <= 1; ++dy) {
        for (int dx = -1; dx <= 1; ++dx) {
          const auto it = cell.find({c.x() + dx, c.y() + dy, c.z() + dz});
          if (it == cell.end() || it->second == i) continue;
          on_boundary = on_boundary || label[it->second] != label[i];
          cut = cut || out.owner[it->second] != out.owner[i];
        }
      }
    }
    boundary += on_boundary ? 1u : 0u;
    recalled += on_boundary && cut ? 1u : 0u;
  }
  Segmentation s;
  s.undersegmentation = static_cast<double>(outside) / static_cast<double>(out.voxels.size());
  s.boundary_recall = boundary > 0 ? static_cast<double>(recalled) / static_cast<double>(boundary) : 1.0;
  s.supervoxels = out.supervoxels.size();
  return s;
}

/// ofv's stage against PCL's on two rendered scenes: a hand holding the
/// case, and a forearm in front of it (640x480, the front end's cloud), with
/// the table's top on a cell face (z = 0) and 3 mm inside a cell (the first
/// once split into two layers of voxels).
TEST(Vccs, SegmentsAboutAsWellAsPcl) {
  const Eigen::Vector3d skin(225, 170, 140);
  for (const double lift : {0.0, 0.003}) {
  for (const bool arm : {false, true}) {
    test::SyntheticScene scene = test::table_and_case({0.0, 0.0, 0.0675 + lift});
    scene.shapes[0] = test::make_box({0.0, 0.0, -0.02 + lift}, {1.6, 1.6, 0.04}, {150, 110, 70}, test::kTable);
    scene.shapes.push_back(
        arm ? test::make_capsule({-0.15, -0.2, 0.08}, {0.05, -0.22, 0.16}, 0.025, skin, test::kHand)
            : test::make_capsule({0.115, -0.005, 0.03}, {0.115, -0.005, 0.12}, 0.02, skin, test::kHand));
    std::vector<int> labels;
    const RgbdFrame frame = scene.render(test::vga(640), test::front_camera(), &labels);
    perception::CloudBuilder builder(perception::CloudSettings{});
    WorldCloud cloud;
    builder.build(frame, {}, cloud);
    SupervoxelOutput mine, pcl;
    perception::detail::vccs_supervoxels(cloud, {}, frame.wMc.translation(), mine);
    perception::detail::cluster_supervoxels(cloud, {}, frame.wMc.translation(), pcl);
    expect_consistent(mine);
    const Segmentation a = measure(mine, frame, labels, 0.008);
    const Segmentation b = measure(pcl, frame, labels, 0.008);
    SCOPED_TRACE(std::string(arm ? "arm in front" : "hand holding the case") + (lift > 0.0 ? ", table inside a cell" : ""));
    EXPECT_LE(a.undersegmentation, b.undersegmentation + 0.002);
    EXPECT_GE(a.boundary_recall, b.boundary_recall - 0.02);
    // The voxels in a supervoxel (alone, or joined with the other half of a
    // surface patch a cell face split): all but the specks and far strips
    // of table no seed reaches, more than PCL's growth keeps.
    perception::detail::PointGrid grid;
    grid.build(mine.voxels, 0.008);
    std::size_t represented = 0;
    for (const Eigen::Vector3f& p : cloud.points) {
      represented += grid.any_within(p, 0.006f, [](int) { return true; }) ? 1u : 0u;
    }
    EXPECT_GE(static_cast<double>(represented), 0.95 * static_cast<double>(cloud.points.size()));
    EXPECT_GT(represented, pcl.voxels.size());
  }
  }
}

}  // namespace
}  // namespace ofv
