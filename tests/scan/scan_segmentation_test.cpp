// Adaptive breakpoint segmentation and the per-cluster reduction of IDCP BoC.
#include <cmath>
#include <numbers>
#include <random>

#include <gtest/gtest.h>

#include "algorithms/scan/scan_match.hpp"
#include "algorithms/scan/scan_segmentation.hpp"
#include "tests/support/scan_room/scan_room.hpp"

namespace facet::scan {
namespace {

constexpr double kDeg = std::numbers::pi / 180.0;

// A scanner looking into a corner: two walls that meet, seen without a gap.
scan_room::Room corner() {
  scan_room::Room room;
  room.walls.push_back({{4.0, -6.0}, {4.0, 3.0}});
  room.walls.push_back({{4.0, 3.0}, {-6.0, 3.0}});
  return room;
}

TEST(SegmentScan, AContinuousCornerIsOneCluster) {
  std::mt19937_64 rng(1);
  const Scan s = scan_room::castScan(corner(), {0, 0, 0}, {}, rng);
  ASSERT_GT(s.size(), 140u);
  const auto clusters = segmentScan(s);
  ASSERT_EQ(clusters.size(), 1u);
  EXPECT_EQ(clusters[0].begin, 0);
  EXPECT_EQ(clusters[0].end, static_cast<int>(s.size()));
}

TEST(SegmentScan, ADepthJumpSplitsClusters) {
  // A wall at 3 m, a pillar at 1.5 m in front of part of it: wall | pillar | wall.
  scan_room::Room room;
  room.walls.push_back({{3.0, -8.0}, {3.0, 8.0}});
  room.addBox({1.5, 0.0}, 0.2, 0.6);
  std::mt19937_64 rng(2);
  const Scan s = scan_room::castScan(room, {0, 0, 0}, {}, rng);
  const auto clusters = segmentScan(s);
  ASSERT_EQ(clusters.size(), 3u);
  int covered = 0;
  for (std::size_t i = 0; i < clusters.size(); ++i) {
    covered += clusters[i].size();
    if (i > 0) {
      EXPECT_EQ(clusters[i].begin, clusters[i - 1].end);
    }
  }
  EXPECT_EQ(covered, static_cast<int>(s.size()));
  // The middle cluster is the pillar: all its points are nearer than the wall.
  for (int i = clusters[1].begin; i < clusters[1].end; ++i) EXPECT_LT(s.points[i].x(), 1.8);
}

TEST(SegmentScan, EmptyAndSinglePointScans) {
  EXPECT_TRUE(segmentScan(Scan{}).empty());
  Scan one;
  one.points = {{1.0, 0.0}};
  const auto clusters = segmentScan(one);
  ASSERT_EQ(clusters.size(), 1u);
  EXPECT_EQ(clusters[0].size(), 1);
  EXPECT_TRUE(reduceClusters(one, clusters, 0.2).scan.empty());  // isolated returns dropped
}

TEST(ReduceClusters, KeepsAboutOnePointPerSpacingAndTheClusters) {
  Scan line;
  for (int i = 0; i <= 100; ++i) line.points.emplace_back(2.0, -1.0 + 0.02 * i);  // 2 m long
  const std::vector<Cluster> clusters{{0, 101}};
  const ClusteredScan reduced = reduceClusters(line, clusters, 0.2);
  ASSERT_EQ(reduced.clusters.size(), 1u);
  EXPECT_EQ(reduced.clusters[0].size(), static_cast<int>(reduced.scan.size()));
  EXPECT_GE(reduced.scan.size(), 9u);
  EXPECT_LE(reduced.scan.size(), 11u);
  for (std::size_t i = 1; i < reduced.scan.size(); ++i) {
    EXPECT_DOUBLE_EQ(reduced.scan.points[i].x(), 2.0);
    EXPECT_GT(reduced.scan.points[i].y(), reduced.scan.points[i - 1].y());  // beam order kept
  }
}

TEST(IdcpBoc, ASingleClusterScanIsMatched) {
  // The whole scan is one cluster (a corner); reduction must not lose the constraint.
  std::mt19937_64 rng(4);
  const scan_room::Room room = corner();
  const ScanPose refPose{0, 0, 0}, newPose{0.3, -0.2, 6 * kDeg};
  const Scan reference = scan_room::castScan(room, refPose, {}, rng);
  const Scan scan = scan_room::castScan(room, newPose, {}, rng);
  ASSERT_EQ(segmentScan(scan).size(), 1u);
  const ScanMatchResult r = matchScans(reference, scan, {}, {});
  EXPECT_TRUE(r.status.ok());
  EXPECT_NEAR(r.pose.x, newPose.x, 0.02);
  EXPECT_NEAR(r.pose.y, newPose.y, 0.02);
  EXPECT_NEAR(r.pose.theta, newPose.theta, 0.3 * kDeg);
}

}  // namespace
}  // namespace facet::scan
