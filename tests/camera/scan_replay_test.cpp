// Scan replay: CSV scans and CARMEN logs from a folder, in natural order, bad files skipped.

#include <cmath>

#include <gtest/gtest.h>

#include "camera/scan_source.hpp"
#include "temp_folder.hpp"

namespace facet {
namespace {

using test::TempFolder;

TEST(ScanReplay, ReplaysCsvAndCarmenInNaturalOrderAndSkipsBadFiles) {
  TempFolder folder;
  folder.write("scan10.csv", "x,y\n1.0,2.0\n3.0,4.0\n");
  folder.write("scan2.csv", "x,y\n0.5,-0.5\n");
  folder.write("broken.csv", "x,y\n1.0,2.0\n1.0,abc\n");
  // Two FLASER messages of 4 beams (-90, -45, 0, 45 degrees) and one message type to skip.
  folder.write("a.log",
               "# CARMEN log\n"
               "ODOM 0 0 0 0 0 0 1.0 host 1.0\n"
               "FLASER 4 1.0 2.0 3.0 4.0 10 20 0.5 0 0 0 12.5 host 12.5\n"
               "FLASER 4 1.5 81.9 2.5 3.5 11 21 0.6 0 0 0 13.5 host 13.5\n");
  ScanReplaySettings settings;
  settings.folder = folder.path();
  auto source = makeScanReplay(settings);

  ScanResult first = source->next();
  ASSERT_TRUE(first) << first.message;
  EXPECT_EQ(first.scan.id, 0u);
  ASSERT_EQ(first.scan.scan.size(), 4u);
  EXPECT_NEAR(first.scan.scan.points[0].x(), 0.0, 1e-12);  // 1 m at -90 degrees
  EXPECT_NEAR(first.scan.scan.points[0].y(), -1.0, 1e-12);
  EXPECT_NEAR(first.scan.scan.points[2].x(), 3.0, 1e-12);  // 3 m straight ahead
  EXPECT_DOUBLE_EQ(first.scan.timestamp_s, 12.5);
  EXPECT_NE(first.scan.source.find("a.log:3"), std::string::npos) << first.scan.source;
  EXPECT_EQ(std::stod(first.scan.metadata.at("pose_x")), 10.0);

  ScanResult second = source->next();
  ASSERT_TRUE(second);
  EXPECT_EQ(second.scan.scan.size(), 3u) << "the 81.9 m no-return beam is dropped";
  EXPECT_NE(second.scan.source.find("a.log:4"), std::string::npos);

  ScanResult third = source->next();  // broken.csv is skipped
  ASSERT_TRUE(third);
  EXPECT_NE(third.scan.source.find("scan2.csv"), std::string::npos) << third.scan.source;
  ASSERT_EQ(third.scan.scan.size(), 1u);
  EXPECT_DOUBLE_EQ(third.scan.scan.points[0].y(), -0.5);

  ScanResult fourth = source->next();
  ASSERT_TRUE(fourth);
  EXPECT_NE(fourth.scan.source.find("scan10.csv"), std::string::npos);
  EXPECT_EQ(fourth.scan.scan.size(), 2u);
  EXPECT_EQ(fourth.scan.id, 3u);

  EXPECT_EQ(source->next().status, GrabStatus::EndOfStream);
  const CameraHealth health = source->health();
  EXPECT_EQ(health.frames, 4u);
  EXPECT_EQ(health.skipped_files, 1u);
  EXPECT_NE(health.last_error.find("broken.csv:3"), std::string::npos) << health.last_error;
}

TEST(ScanReplay, GlobLoopAndRangeLimit) {
  TempFolder folder;
  folder.write("keep.csv", "angle_deg,range\n0,1.0\n90,5.0\n");
  folder.write("other.csv", "x,y\n9,9\n");
  ScanReplaySettings settings;
  settings.folder = folder.path();
  settings.glob = "keep*";
  settings.loop = true;
  settings.max_range_m = 4.0;
  auto source = makeScanReplay(settings);
  for (int i = 0; i < 3; ++i) {
    ScanResult r = source->next();
    ASSERT_TRUE(r) << r.message;
    ASSERT_EQ(r.scan.scan.size(), 1u) << "the 5 m beam is beyond max_range_m";
    EXPECT_NEAR(r.scan.scan.points[0].x(), 1.0, 1e-12);
    EXPECT_EQ(r.scan.id, static_cast<std::uint64_t>(i));
  }
}

TEST(ScanReplay, EmptyOrMissingFolderIsAnError) {
  TempFolder folder;
  ScanReplaySettings settings;
  settings.folder = folder.path();
  EXPECT_THROW(makeScanReplay(settings), CameraError);
  settings.folder = folder / "missing";
  EXPECT_THROW(makeScanReplay(settings), CameraError);
  folder.write("bad.csv", "x,y\nnope\n");
  settings.folder = folder.path();
  settings.loop = true;
  auto source = makeScanReplay(settings);
  EXPECT_EQ(source->next().status, GrabStatus::Error);  // only bad files, even with loop
}

}  // namespace
}  // namespace facet
