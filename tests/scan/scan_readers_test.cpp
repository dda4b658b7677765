// CARMEN log and CSV scan readers: beams to points, skipped message types, dropped bad ranges,
// and errors that name the source and the line.
#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <sstream>
#include <string>

#include <gtest/gtest.h>

#include "algorithms/scan/carmen_log.hpp"
#include "algorithms/scan/scan_csv.hpp"
#include "algorithms/scan/scan_file.hpp"

namespace facet::scan {
namespace {

// A FLASER line with `n` beams of range `range` (with overrides) and the given pose.
std::string flaser(int n, double range, const std::string& overrides = "") {
  std::ostringstream out;
  out << "FLASER " << n;
  for (int i = 0; i < n; ++i) {
    if (i == 1 && !overrides.empty())
      out << " " << overrides;
    else
      out << " " << range;
  }
  out << " 1.5 -2.0 0.25 1.4 -2.1 0.2 1071078718.5 host 0.3\n";
  return out.str();
}

int lineOf(const auto& read) {
  try {
    read();
  } catch (const ScanFormatError& e) {
    return e.line;
  }
  return -1;
}

TEST(CarmenLog, ReadsFlaserAndSkipsOtherMessages) {
  std::istringstream in(
      "# message formats defined: PARAM SYNC ODOM FLASER RLASER\n"
      "PARAM robot_front_laser_max 80.99 0 host 0\n"
      "ODOM 0 0 0 0 0 0 0 host 0\n" +
      flaser(4, 2.0) +  // 4 beams: -90, -45, 0, 45 deg
      "NEFF 1 2 3\n" + flaser(5, 3.0, "nan"));
  const auto scans = readCarmenLog(in, "mem.log");
  ASSERT_EQ(scans.size(), 2u);
  EXPECT_EQ(scans[0].line, 4);
  EXPECT_EQ(scans[1].line, 6);
  ASSERT_EQ(scans[0].scan.size(), 4u);
  EXPECT_NEAR(scans[0].scan.points[0].x(), 0.0, 1e-12);  // beam 0 looks right (-y)
  EXPECT_NEAR(scans[0].scan.points[0].y(), -2.0, 1e-12);
  EXPECT_NEAR(scans[0].scan.points[2].x(), 2.0, 1e-12);  // beam n/2 looks forward
  EXPECT_NEAR(scans[0].scan.points[3].x(), 2.0 * std::cos(std::numbers::pi / 4), 1e-12);
  EXPECT_NEAR(scans[0].pose.x, 1.5, 1e-12);
  EXPECT_NEAR(scans[0].pose.y, -2.0, 1e-12);
  EXPECT_NEAR(scans[0].pose.theta, 0.25, 1e-12);
  EXPECT_NEAR(scans[0].odometry.x, 1.4, 1e-12);
  EXPECT_NEAR(scans[0].timestamp, 1071078718.5, 1e-6);
  // 5 beams (odd): step 180 / 4 deg, so the last beam looks left; the NaN beam is dropped.
  ASSERT_EQ(scans[1].scan.size(), 4u);
  EXPECT_NEAR(scans[1].scan.points.back().y(), 3.0, 1e-12);
}

TEST(CarmenLog, MaxRangeAndInfBeamsAreDropped) {
  std::istringstream in(flaser(3, 81.91, "inf") + flaser(3, 1.0, "0"));
  const auto scans = readCarmenLog(in, "mem.log");
  ASSERT_EQ(scans.size(), 2u);
  EXPECT_TRUE(scans[0].scan.empty());
  EXPECT_EQ(scans[1].scan.size(), 2u);  // range 0 is no echo
}

TEST(CarmenLog, BadLinesNameSourceAndLine) {
  const auto read = [](const std::string& text) {
    return [text] {
      std::istringstream in(text);
      (void)readCarmenLog(in, "run.log");
    };
  };
  EXPECT_EQ(lineOf(read("PARAM a b\n" + flaser(3, 1.0) + "FLASER 3 1 1\n")), 3);
  EXPECT_EQ(lineOf(read(flaser(3, 1.0, "x1.2"))), 1);
  EXPECT_EQ(lineOf(read("\n\nFLASER many 1 2 3\n")), 3);
  EXPECT_EQ(lineOf(read("FLASER 2 1 1 0 0 nan 0 0 0 0 h 0\n")), 1);
  try {
    read("ODOM\n" + flaser(3, 1.0, "abc"))();
    FAIL() << "no error";
  } catch (const ScanFormatError& e) {
    EXPECT_EQ(e.source, "run.log");
    EXPECT_NE(std::string(e.what()).find("run.log:2: "), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("abc"), std::string::npos) << e.what();
  }
}

TEST(CarmenLog, ReadsTheGzippedIntelLog) {
  const std::filesystem::path file =
      std::filesystem::path(FACET_TEST_DATA_DIR) / "carmen-scans/intel-corrected.log.gz";
  ASSERT_TRUE(std::filesystem::exists(file)) << file;
  const auto scans = readCarmenLogFile(file.string());
  ASSERT_EQ(scans.size(), 910u);  // the README: 910 scans x 180 beams
  for (const auto& s : scans) {
    ASSERT_LE(s.scan.size(), 180u);
    for (const auto& p : s.scan.points) ASSERT_LT(p.norm(), 80.0);
  }
  EXPECT_GT(scans[0].scan.size(), 100u);
}

TEST(ScanFile, MissingFileIsNamed) {
  try {
    (void)readScanCsvFile("/nonexistent/scan.csv");
    FAIL() << "no error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/scan.csv"), std::string::npos);
  }
}

TEST(ScanCsv, XyWithAndWithoutHeader) {
  std::istringstream plain("1.0,2.0\n# comment\n\n3.5, -4\n");
  const Scan a = readScanCsv(plain, "a.csv");
  ASSERT_EQ(a.size(), 2u);
  EXPECT_DOUBLE_EQ(a.points[1].x(), 3.5);
  EXPECT_DOUBLE_EQ(a.points[1].y(), -4.0);

  std::istringstream header("y,x\n1,2\nnan,3\n4,inf\n");  // columns by name; NaN/inf rows dropped
  const Scan b = readScanCsv(header, "b.csv");
  ASSERT_EQ(b.size(), 1u);
  EXPECT_DOUBLE_EQ(b.points[0].x(), 2.0);
  EXPECT_DOUBLE_EQ(b.points[0].y(), 1.0);
}

TEST(ScanCsv, AngleAndRangeWithHeader) {
  std::istringstream in("angle_deg,range\n-90,2\n0,1.5\n45,nan\n60,inf\n90,81.91\n90,1\n");
  const Scan s = readScanCsv(in, "p.csv");
  ASSERT_EQ(s.size(), 3u);
  EXPECT_NEAR(s.points[0].x(), 0.0, 1e-12);
  EXPECT_NEAR(s.points[0].y(), -2.0, 1e-12);
  EXPECT_NEAR(s.points[1].x(), 1.5, 1e-12);
  EXPECT_NEAR(s.points[2].y(), 1.0, 1e-12);
}

TEST(ScanCsv, BadLinesNameSourceAndLine) {
  const auto read = [](const std::string& text) {
    return [text] {
      std::istringstream in(text);
      (void)readScanCsv(in, "bad.csv");
    };
  };
  EXPECT_EQ(lineOf(read("x,y\n1,2\n3,four\n")), 3);
  EXPECT_EQ(lineOf(read("1,2\n3,4,5\n")), 2);
  EXPECT_EQ(lineOf(read("# scan\nforward,left\n1,2\n")), 2);  // unknown header
  EXPECT_EQ(lineOf(read("angle_deg,range\n10\n")), 2);
  try {
    read("1,2\n\n1;2\n")();
    FAIL() << "no error";
  } catch (const ScanFormatError& e) {
    EXPECT_EQ(std::string(e.what()).rfind("bad.csv:3: ", 0), 0u) << e.what();
  }
}

}  // namespace
}  // namespace facet::scan
