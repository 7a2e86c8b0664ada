// Occluder clusters and their constant-velocity tracks, on scenes with known motion.
#include "ofv/occluder_tracker.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <limits>
#include <random>

namespace ofv {
namespace {

// A 4 x 4 x 2 block of points 2 cm apart, its first corner at `corner`.
Eigen::Matrix3Xd block(const Eigen::Vector3d& corner, int nx = 4) {
  Eigen::Matrix3Xd p(3, nx * 8);
  for (int k = 0; k < nx * 8; ++k) p.col(k) = corner + 0.02 * Eigen::Vector3d(k % nx, (k / nx) % 4, k / (nx * 4));
  return p;
}

Eigen::Matrix3Xd join(const Eigen::Matrix3Xd& a, const Eigen::Matrix3Xd& b) {
  Eigen::Matrix3Xd out(3, a.cols() + b.cols());
  out << a, b;
  return out;
}

TEST(OccluderTracker, ClustersAreChainsOfNearPoints) {
  // Two blocks 10 cm apart at 5 cm linkage: two clusters; a bridge of points
  // 3 to 3.5 cm apart joins them into one.
  const Eigen::Matrix3Xd two = join(block({0, 0, 0}), block({0.16, 0, 0}));
  auto clusters = cluster_points(two, 0.05);
  ASSERT_EQ(clusters.size(), 2U);
  EXPECT_EQ(clusters[0].size(), 32U);
  EXPECT_EQ(clusters[0].front(), 0);
  EXPECT_EQ(clusters[1].front(), 32);
  Eigen::Matrix3Xd bridge(3, 2);
  bridge << 0.095, 0.125, 0.0, 0.0, 0.0, 0.0;
  EXPECT_EQ(cluster_points(join(two, bridge), 0.05).size(), 1U);
  // Non-finite points belong to no cluster.
  Eigen::Matrix3Xd bad = two;
  bad(0, 3) = std::nan("");
  clusters = cluster_points(bad, 0.05);
  EXPECT_EQ(clusters[0].size() + clusters[1].size(), 63U);
}

// Single linkage by its definition: every pair closer than `link` joined.
std::vector<std::vector<int>> clusters_by_every_pair(const Eigen::Matrix3Xd& p, double link) {
  const auto n = static_cast<int>(p.cols());
  std::vector<int> label(static_cast<std::size_t>(n), -1);
  std::vector<std::vector<int>> clusters;
  for (int seed = 0; seed < n; ++seed) {
    if (label[static_cast<std::size_t>(seed)] >= 0 || !p.col(seed).allFinite()) continue;
    const int id = static_cast<int>(clusters.size());
    std::vector<int> members{seed};
    label[static_cast<std::size_t>(seed)] = id;
    for (std::size_t k = 0; k < members.size(); ++k) {
      for (int j = 0; j < n; ++j) {
        if (label[static_cast<std::size_t>(j)] < 0 && p.col(j).allFinite() &&
            (p.col(members[k]) - p.col(j)).squaredNorm() < link * link) {
          label[static_cast<std::size_t>(j)] = id;
          members.push_back(j);
        }
      }
    }
    std::sort(members.begin(), members.end());
    clusters.push_back(members);
  }
  return clusters;
}

TEST(OccluderTracker, ClustersEqualThoseOfJoiningEveryNearPair) {
  // Random clouds from sparse to dense, with points on cell boundaries,
  // far-out points (beyond any cell index) and non-finite ones.
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  for (int trial = 0; trial < 60; ++trial) {
    const double link = trial % 3 == 0 ? 0.05 : (trial % 3 == 1 ? 0.013 : 0.2);
    const int n = 20 + 40 * (trial % 7);
    const double extent = 0.1 + 0.1 * (trial % 5);
    Eigen::Matrix3Xd p(3, n);
    for (int i = 0; i < n; ++i) p.col(i) = extent * Eigen::Vector3d(unit(rng), unit(rng), unit(rng));
    if (trial % 4 == 0) p.col(1) = Eigen::Vector3d(link, 0.5 * link, -link);  // on cell corners
    if (trial % 4 == 0) p.col(2) = Eigen::Vector3d(link, 0.5 * link, -0.5 * link);
    if (trial % 5 == 0) p.col(3) = Eigen::Vector3d(1e300, 0.0, 0.0);
    if (trial % 5 == 0) p.col(4) = Eigen::Vector3d(1e300, 0.0, 0.01 * link);  // linked to the one above
    if (trial % 6 == 0) p(1, 5) = std::numeric_limits<double>::infinity();
    EXPECT_EQ(cluster_points(p, link), clusters_by_every_pair(p, link)) << "trial " << trial;
  }
  // Far apart clusters: the grid falls back from a table to a hash map.
  Eigen::Matrix3Xd spread = join(block({0, 0, 0}), block({5000.0, -3000.0, 2000.0}));
  EXPECT_EQ(cluster_points(spread, 0.05), clusters_by_every_pair(spread, 0.05));
}

TEST(OccluderTracker, VelocityOfANoisyTranslatingClusterWithinThreeCentimetresPerSecond) {
  // A hand-sized cluster moving at (0.6, -0.2, 0.1) m/s, 30 frames a second,
  // every point with 3 mm of noise: after half a second the velocity is
  // within 3 cm/s and the track was confirmed with one id throughout.
  const Eigen::Vector3d v(0.6, -0.2, 0.1);
  const double dt = 1.0 / 30.0;
  std::mt19937 rng(7);
  std::normal_distribution<double> noise(0.0, 0.003);
  OccluderTracker tracker;
  for (int k = 0; k <= 15; ++k) {
    Eigen::Matrix3Xd p = block(Eigen::Vector3d(-0.3, 0.1, 0.3) + k * dt * v);
    for (Eigen::Index i = 0; i < p.size(); ++i) p.data()[i] += noise(rng);
    const auto& tracks = tracker.update(p, dt);
    ASSERT_EQ(tracks.size(), 1U);
    EXPECT_EQ(tracks[0].id, 0);
  }
  const OccluderTrack& t = tracker.tracks()[0];
  EXPECT_TRUE(t.confirmed);
  EXPECT_LT((t.velocity - v).norm(), 0.03) << t.velocity.transpose();
  EXPECT_GT(t.speed_sigma(), 0.0);
  EXPECT_EQ(t.points.cols(), 32);
}

TEST(OccluderTracker, AStillOccluderWhoseVisiblePartGrowsStaysStill) {
  // An arm entering the sphere: its visible part grows by one 2 cm column a
  // frame, so its centroid moves at 30 cm/s, yet the arm does not move.
  OccluderTracker tracker;
  for (int k = 0; k < 12; ++k) (void)tracker.update(block({0, 0, 0.3}, 4 + k), 1.0 / 30.0);
  ASSERT_EQ(tracker.tracks().size(), 1U);
  EXPECT_LT(tracker.tracks()[0].velocity.norm(), 0.05) << tracker.tracks()[0].velocity.transpose();
}

TEST(OccluderTracker, TwoOccludersKeepTheirTracksAndALostOneIsDropped) {
  const double dt = 0.05;
  OccluderTracker tracker;
  for (int k = 0; k < 10; ++k) {
    const double s = k * dt;
    (void)tracker.update(join(block({-0.4 + 0.5 * s, 0, 0.3}), block({0.4 - 0.3 * s, 0.2, 0.3})), dt);
  }
  ASSERT_EQ(tracker.tracks().size(), 2U);
  EXPECT_NEAR(tracker.tracks()[0].velocity.x(), 0.5, 0.02);
  EXPECT_NEAR(tracker.tracks()[1].velocity.x(), -0.3, 0.02);
  // The second leaves: it coasts for max_misses frames, then is dropped.
  const int misses = tracker.settings().max_misses;
  const auto first = [&](int k) { return block({-0.4 + 0.5 * k * dt, 0, 0.3}); };
  for (int k = 10; k < 10 + misses; ++k) (void)tracker.update(first(k), dt);
  EXPECT_EQ(tracker.tracks().size(), 2U);
  EXPECT_EQ(tracker.tracks()[1].points.cols(), 0);
  (void)tracker.update(first(10 + misses), dt);
  ASSERT_EQ(tracker.tracks().size(), 1U);
  EXPECT_EQ(tracker.tracks()[0].id, 0);
}

// A still table top in the plane y = 0: 21 x 21 points 2 cm apart.
Eigen::Matrix3Xd table_top() {
  Eigen::Matrix3Xd table(3, 21 * 21);
  for (int k = 0; k < 21 * 21; ++k) table.col(k) = Eigen::Vector3d(-0.2 + 0.02 * (k % 21), 0.0, 0.2 + 0.02 * (k / 21));
  return table;
}

// A hand (a block of 32 points) sliding at 0.6 m/s along x from x = `from`,
// `above` over the table top, for `frames` frames: the hand and the table
// are two tracks every frame; at the end the hand, whose track began
// first when `hand_first`, has its own velocity, the table none.
void expect_hand_and_table(double from, double above, int frames, bool hand_first) {
  const Eigen::Matrix3Xd table = table_top();
  const double dt = 1.0 / 30.0;
  const double speed = 0.6;
  OccluderTracker tracker;
  for (int k = 0; k < frames; ++k) {
    const Eigen::Matrix3Xd hand = block({from + speed * k * dt, -above - 0.06, 0.4});
    const auto& tracks = tracker.update(hand_first ? join(hand, table) : join(table, hand), dt);
    ASSERT_EQ(tracks.size(), 2U) << "frame " << k;
    EXPECT_EQ(tracks[hand_first ? 0 : 1].points.cols(), 32) << "frame " << k;
  }
  const OccluderTrack& hand = tracker.tracks()[hand_first ? 0 : 1];
  const OccluderTrack& still = tracker.tracks()[hand_first ? 1 : 0];
  EXPECT_EQ(hand.id, hand_first ? 0 : 1);
  EXPECT_LT((hand.velocity - Eigen::Vector3d(speed, 0, 0)).norm(), 0.03) << hand.velocity.transpose();
  EXPECT_LT(still.velocity.norm(), 0.01) << still.velocity.transpose();
  EXPECT_EQ(still.points.cols(), 21 * 21);
}

TEST(OccluderTracker, AHandThatReachesTheTableKeepsItsTrackAndVelocity) {
  // A hand slides over a still table, 4 cm above it: from the 12th frame
  // on, single linkage joins them into one cluster. The cluster is cut
  // back between the two tracks: the hand keeps its id and velocity, the
  // table stays still (one cluster would move at neither speed).
  expect_hand_and_table(-0.5, 0.04, 30, /*hand_first=*/true);
}

TEST(OccluderTracker, AHandSeenOnlyAgainstTheTableHasItsOwnTrack) {
  // A hand slides 3 cm above a still table from the first frame on: single
  // linkage never sees them apart. The wide plane is cut from what lies
  // off it: the hand has its own track and velocity (measured with the
  // table, only along the table's normal, it was still), the table stays
  // still.
  expect_hand_and_table(-0.2, 0.03, 15, /*hand_first=*/false);
}

// A capsule's camera-facing half, axis along x, radius 3 cm, `length` long,
// its centre at `centre`; points about 1.5 cm apart.
Eigen::Matrix3Xd capsule_along_x(const Eigen::Vector3d& centre, double length) {
  std::vector<Eigen::Vector3d> p;
  const double radius = 0.03;
  for (double x = -0.5 * length; x <= 0.5 * length + 1e-9; x += 0.015) {
    for (int k = 0; k <= 6; ++k) {
      const double a = EIGEN_PI * k / 6.0;  // the half facing -z
      p.emplace_back(centre + Eigen::Vector3d(x, radius * std::cos(a), -radius * std::sin(a)));
    }
  }
  Eigen::Matrix3Xd m(3, static_cast<Eigen::Index>(p.size()));
  for (std::size_t k = 0; k < p.size(); ++k) m.col(static_cast<Eigen::Index>(k)) = p[k];
  return m;
}

TEST(OccluderTracker, AHandThatStopsIsStillWithinAFewFrames) {
  // A forearm (a 40 cm capsule, its ends outside the part seen: only its
  // middle 20 cm) moves along its axis at 0.5 m/s, then stops. Along the
  // axis its shape cannot tell motion: registration from the predicted
  // motion alone kept the track moving for ever.
  const double dt = 1.0 / 30.0;
  const auto seen = [](const Eigen::Matrix3Xd& p) {  // the part between x = -0.1 and 0.1
    std::vector<Eigen::Index> keep;
    for (Eigen::Index k = 0; k < p.cols(); ++k) {
      if (std::abs(p(0, k)) <= 0.1) keep.push_back(k);
    }
    return Eigen::Matrix3Xd(p(Eigen::all, keep));
  };
  OccluderTracker tracker;
  double x = -0.2;
  for (int k = 0; k < 15; ++k, x += 0.5 * dt) (void)tracker.update(seen(capsule_along_x({x, 0, 0.3}, 0.4)), dt);
  for (int k = 0; k < 6; ++k) (void)tracker.update(seen(capsule_along_x({x, 0, 0.3}, 0.4)), dt);
  ASSERT_EQ(tracker.tracks().size(), 1U);
  EXPECT_LT(tracker.tracks()[0].velocity.norm(), 0.05) << tracker.tracks()[0].velocity.transpose();
}

TEST(OccluderTracker, AMovingCapsuleWhoseEndsAreSeenKeepsItsVelocity) {
  const double dt = 1.0 / 30.0;
  const Eigen::Vector3d v(0.6, 0.0, 0.0);  // along its axis
  OccluderTracker tracker;
  for (int k = 0; k < 15; ++k) (void)tracker.update(capsule_along_x(Eigen::Vector3d(-0.3, 0, 0.3) + k * dt * v, 0.1), dt);
  ASSERT_EQ(tracker.tracks().size(), 1U);
  EXPECT_LT((tracker.tracks()[0].velocity - v).norm(), 0.05) << tracker.tracks()[0].velocity.transpose();
}

TEST(OccluderTracker, ATableWhosePartInViewChangesStaysStill) {
  // A still table top (y = 0.08) of which the part seen slides by 2 cm a
  // frame (the camera turns): its motion within its plane cannot be seen,
  // only along its normal; the track stays still.
  const double dt = 1.0 / 30.0;
  OccluderTracker tracker;
  for (int f = 0; f < 12; ++f) {
    Eigen::Matrix3Xd p(3, 10 * 10);
    for (int k = 0; k < 100; ++k) p.col(k) = Eigen::Vector3d(-0.1 + 0.02 * (k % 10 + f), 0.08, 0.4 + 0.02 * (k / 10));
    (void)tracker.update(p, dt);
  }
  ASSERT_EQ(tracker.tracks().size(), 1U);
  EXPECT_LT(tracker.tracks()[0].velocity.norm(), 0.02) << tracker.tracks()[0].velocity.transpose();
}

TEST(OccluderTracker, ATableThatComesIntoViewStaysStill) {
  // A still table top first seen as 3 points at a corner, then as a
  // 12 cm square (it comes into view): most of the new points are far from
  // the old ones (the old ones all find theirs, at no motion).
  const double dt = 1.0 / 30.0;
  Eigen::Matrix3Xd table(3, 49);
  for (int k = 0; k < 49; ++k) table.col(k) = Eigen::Vector3d(0.02 * (k % 7), 0.08, 0.4 + 0.02 * (k / 7));
  OccluderTracker tracker;
  (void)tracker.update(table.leftCols(3), dt);
  for (int f = 0; f < 3; ++f) (void)tracker.update(table, dt);
  ASSERT_EQ(tracker.tracks().size(), 1U);
  EXPECT_LT(tracker.tracks()[0].velocity.norm(), 0.05) << tracker.tracks()[0].velocity.transpose();
}

TEST(OccluderTracker, ATrackThatBecomesAWidePlaneHasNoMotionWithinIt) {
  // A small flat patch of the table top (4 x 2 points, too narrow to be a
  // wide plane) slides at 0.4 m/s along x, as a piece of table seen past
  // the object does while the camera moves; then the whole table top is
  // seen, one cluster with it. A wide plane's motion within itself is not
  // seen: the track has none from that frame on (the Kalman filter alone
  // took five frames to forget it, predicting the table across the view).
  const double dt = 1.0 / 30.0;
  const double speed = 0.4;
  OccluderTracker tracker;
  for (int f = 0; f < 10; ++f) {
    Eigen::Matrix3Xd patch(3, 8);
    for (int k = 0; k < 8; ++k) {
      patch.col(k) = Eigen::Vector3d(-0.15 + speed * f * dt + 0.02 * (k % 4), 0.0, 0.39 + 0.02 * (k / 4));
    }
    (void)tracker.update(patch, dt);
  }
  ASSERT_EQ(tracker.tracks().size(), 1U);
  ASSERT_GT(tracker.tracks()[0].velocity.x(), 0.3) << tracker.tracks()[0].velocity.transpose();
  (void)tracker.update(table_top(), dt);
  ASSERT_EQ(tracker.tracks().size(), 1U);
  EXPECT_EQ(tracker.tracks()[0].id, 0);
  EXPECT_LT(tracker.tracks()[0].velocity.norm(), 1e-9) << tracker.tracks()[0].velocity.transpose();
}

TEST(OccluderTracker, APieceOfAWidePlaneHasNoMotionWithinIt) {
  // The table top, and apart from it (10 cm off its edge) a small flat
  // piece in its plane that slides along x at 0.4 m/s: what a piece of
  // table seen past the object looks like while the camera moves (the part
  // in view changes). Too small to be a wide plane itself, it lies in one:
  // measured along the plane's normal only, it stays still. A block of the
  // same size 3 cm above the plane keeps its motion.
  const double dt = 1.0 / 30.0;
  const double speed = 0.4;
  for (const double above : {0.0, 0.03}) {
    OccluderTracker tracker;
    for (int f = 0; f < 12; ++f) {
      Eigen::Matrix3Xd piece(3, 8);
      for (int k = 0; k < 8; ++k) {
        piece.col(k) = Eigen::Vector3d(0.3 + speed * f * dt + 0.02 * (k % 4), -above, 0.39 + 0.02 * (k / 4));
      }
      (void)tracker.update(join(table_top(), piece), dt);
    }
    ASSERT_EQ(tracker.tracks().size(), 2U) << above;
    EXPECT_LT(tracker.tracks()[0].velocity.norm(), 1e-9) << tracker.tracks()[0].velocity.transpose();
    const Eigen::Vector3d v = tracker.tracks()[1].velocity;
    if (above == 0.0) {
      EXPECT_LT(v.norm(), 1e-9) << v.transpose();
    } else {
      EXPECT_LT((v - Eigen::Vector3d(speed, 0, 0)).norm(), 0.03) << v.transpose();
    }
  }
}

// A track seen this frame: a block of points at `at`, moving at `vx` along x.
OccluderTrack track(double vx, const Eigen::Vector3d& at, bool confirmed = true) {
  OccluderTrack t;
  t.confirmed = confirmed;
  t.velocity << vx, 0, 0;
  t.points = block(at);
  return t;
}

TEST(OccluderTracker, PredictionShiftsMovingTracksOnly) {
  const OccluderTrack moving = track(0.5, {0, 0, 0});
  const OccluderTrack still = track(0.01, {0, 0, 0});
  const OccluderTrack unconfirmed = track(0.5, {0, 0, 0}, false);
  const Eigen::Matrix3Xd ahead = predicted_occluders({moving, still, unconfirmed}, {0.2, 0.4}, 0.05);
  ASSERT_EQ(ahead.cols(), 64);
  EXPECT_TRUE(ahead.leftCols(32).isApprox(moving.points.colwise() + Eigen::Vector3d(0.1, 0, 0)));
  EXPECT_TRUE(ahead.rightCols(32).isApprox(moving.points.colwise() + Eigen::Vector3d(0.2, 0, 0)));
  EXPECT_EQ(predicted_occluders({still}, {0.2}, 0.05).cols(), 0);
}

TEST(OccluderTracker, StillOccludersAreTheConfirmedSlowTracksSeenThisFrame) {
  const OccluderTrack moving = track(0.5, {0, 0, 0});
  const OccluderTrack still = track(0.01, {0.3, 0, 0});
  const OccluderTrack unconfirmed = track(0.01, {0.3, 0, 0}, false);  // new: not known to stand still yet
  OccluderTrack missed = still;  // not seen this frame
  missed.points.resize(3, 0);
  EXPECT_TRUE(is_moving(moving, 0.05));
  EXPECT_FALSE(is_still(moving, 0.05));
  EXPECT_TRUE(is_still(still, 0.05));
  EXPECT_FALSE(is_moving(still, 0.05));
  EXPECT_FALSE(is_still(unconfirmed, 0.05) || is_moving(unconfirmed, 0.05));
  EXPECT_FALSE(is_still(missed, 0.05) || is_moving(missed, 0.05));
  const Eigen::Matrix3Xd points = still_occluders({moving, unconfirmed, still, missed}, 0.05);
  ASSERT_EQ(points.cols(), still.points.cols());
  EXPECT_EQ(points, still.points);
  // The same track is still or moving by the threshold.
  EXPECT_EQ(still_occluders({moving}, 1.0).cols(), moving.points.cols());
}

TEST(OccluderTracker, HostilePointsLeaveTheOthersTracked) {
  // A table with a hand just above it, and among them points that are not
  // finite, repeated, or far beyond any cell index: the table and the hand
  // are still tracked apart, the table still, every finite track finite.
  const Eigen::Matrix3Xd table = table_top();
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  Eigen::Matrix3Xd odd(3, 6);
  odd << nan, 1e200, 1e200, 0.0, -inf, 1e200,  //
      0.0, 0.0, 0.0, nan, 0.0, 1e200,          //
      0.0, 0.0, 0.0, 0.4, 0.0, -1e200;
  const double dt = 1.0 / 30.0;
  OccluderTracker tracker;
  for (int k = 0; k < 6; ++k) {
    const Eigen::Matrix3Xd frame = join(join(table, block({-0.2 + 0.02 * k, -0.09, 0.4})), join(odd, table.leftCols(30)));
    (void)tracker.update(frame, dt);
  }
  int near = 0;
  for (const OccluderTrack& t : tracker.tracks()) {
    if (t.position.norm() > 1.0) continue;  // the far points' own tracks
    ++near;
    EXPECT_TRUE(t.position.allFinite() && t.velocity.allFinite());
  }
  EXPECT_EQ(near, 2);
  EXPECT_LT(tracker.tracks()[0].velocity.norm(), 0.01) << tracker.tracks()[0].velocity.transpose();
}

TEST(OccluderTracker, SettingsAndPeriodsAreValidated) {
  TrackerSettings s;
  s.link_distance = 0.0;
  EXPECT_THROW((OccluderTracker(s)), std::invalid_argument);
  s = {};
  s.accel_noise = std::numeric_limits<double>::infinity();
  EXPECT_THROW((OccluderTracker(s)), std::invalid_argument);
  OccluderTracker tracker;
  (void)tracker.update(block({0, 0, 0}), 0.0);  // the first frame's period is not used
  EXPECT_THROW((void)tracker.update(block({0, 0, 0}), -1.0), std::invalid_argument);
}

}  // namespace
}  // namespace ofv
