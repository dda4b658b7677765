// `facet scan-match` run as a process on CSV files: JSON output, methods, --init, and errors.
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <random>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "tests/support/cli/facet_cli.hpp"
#include "tests/support/scan_room/scan_room.hpp"

namespace {

namespace fs = std::filesystem;
using facet::scan::Scan;
using facet::scan::ScanPose;

using facet::test::CliRun;
CliRun runCli(const std::string& args) {
  return facet::test::runFacet(args);
}

class ScanMatchCli : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("facet_scan_cli_" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()) +
            "_" + ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::create_directories(dir_);
    std::mt19937_64 rng(3);
    const auto room = facet::scan_room::officeRoom();
    refPose_ = {5.0, 4.0, 0.5};
    newPose_ = {5.2, 3.9, 0.6};
    truth_ = refPose_.inverse() * newPose_;
    writeXy(ref(), facet::scan_room::castScan(room, refPose_, {}, rng));
    // The second scan as angle_deg,range to exercise both CSV layouts.
    const facet::scan_room::ScannerSpec spec;
    const auto ranges = facet::scan_room::castRanges(room, newPose_, spec, rng);
    std::ofstream out(scan());
    out << "angle_deg,range\n";
    for (std::size_t i = 0; i < ranges.size(); ++i)
      out << (spec.firstAngle + static_cast<double>(i) * spec.angleStep) * 180.0 / std::numbers::pi
          << "," << ranges[i] << "\n";
  }
  void TearDown() override { fs::remove_all(dir_); }

  static void writeXy(const fs::path& path, const Scan& s) {
    std::ofstream out(path);
    out << "x,y\n";
    for (const auto& p : s.points) out << p.x() << "," << p.y() << "\n";
  }
  [[nodiscard]] std::string ref() const { return (dir_ / "ref.csv").string(); }
  [[nodiscard]] std::string scan() const { return (dir_ / "scan.csv").string(); }

  fs::path dir_;
  ScanPose refPose_, newPose_, truth_;
};

TEST_F(ScanMatchCli, EveryMethodPrintsThePoseAsJson) {
  for (const std::string method : {"icp", "icp-line", "dcp", "idcp"}) {
    const CliRun r = runCli("scan-match --ref " + ref() + " --scan " + scan() + " --method " +
                            method + " --json");
    ASSERT_EQ(r.exitCode, 0) << method << ": " << r.out;
    const auto j = nlohmann::json::parse(r.out);
    EXPECT_NEAR(j.at("x").get<double>(), truth_.x, 0.03) << method;
    EXPECT_NEAR(j.at("y").get<double>(), truth_.y, 0.03) << method;
    EXPECT_NEAR(j.at("theta").get<double>(), truth_.theta * 180.0 / std::numbers::pi, 0.5)
        << method;  // degrees
    EXPECT_TRUE(j.at("converged").get<bool>());
    EXPECT_GT(j.at("iterations").get<int>(), 0);
    EXPECT_LT(j.at("rms").get<double>(), 0.05);
    EXPECT_GE(j.at("time_ms").get<double>(), 0.0);
  }
}

TEST_F(ScanMatchCli, InitialPoseIsUsed) {
  // A start near the truth converges to it; the same --init in metres and degrees.
  const CliRun r =
      runCli("scan-match --ref " + ref() + " --scan " + scan() +
             " --init=" + std::to_string(truth_.x + 0.1) + "," + std::to_string(truth_.y) + "," +
             std::to_string(truth_.theta * 180.0 / std::numbers::pi + 3.0) + " --json");
  ASSERT_EQ(r.exitCode, 0) << r.out;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_NEAR(j.at("x").get<double>(), truth_.x, 0.03);
}

TEST_F(ScanMatchCli, BadInputExitsWithOne) {
  EXPECT_EQ(runCli("scan-match --ref /nonexistent.csv --scan " + scan() + " --json").exitCode, 1);
  EXPECT_EQ(runCli("scan-match --ref " + ref() + " --scan " + scan() + " --method sgd").exitCode,
            1);
  EXPECT_EQ(runCli("scan-match --ref " + ref() + " --scan " + scan() + " --init 1,2").exitCode, 1);
  {
    std::ofstream bad(dir_ / "bad.csv");
    bad << "x,y\n1,2\n3,oops\n";
  }
  const std::string command = std::string(FACET_CLI) + " scan-match --ref " +
                              (dir_ / "bad.csv").string() + " --scan " + scan() + " 2>&1";
  FILE* pipe = popen(command.c_str(), "r");
  ASSERT_NE(pipe, nullptr);
  char buffer[4096];
  std::string err;
  while (const std::size_t n = std::fread(buffer, 1, sizeof(buffer), pipe)) err.append(buffer, n);
  EXPECT_NE(pclose(pipe), 0);
  EXPECT_NE(err.find("bad.csv:3:"), std::string::npos) << err;
}

TEST_F(ScanMatchCli, EmptyScanIsAMeasurementFailure) {
  {
    std::ofstream empty(dir_ / "empty.csv");
    empty << "x,y\n";
  }
  const CliRun r =
      runCli("scan-match --ref " + ref() + " --scan " + (dir_ / "empty.csv").string() + " --json");
  EXPECT_EQ(r.exitCode, 2);
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j.at("error").at("cause"), "empty_scan");
}

}  // namespace
