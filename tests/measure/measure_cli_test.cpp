// `facet caliper`, `facet line` and `facet blob` end to end: a generated scene written to disk,
// the real binary, its JSON, its exit codes and messages.
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "tests/support/cli/facet_cli.hpp"
#include "tests/support/scene/scene.hpp"

namespace {

namespace fs = std::filesystem;
using facet::test::CliRun;

CliRun facet(const std::string& args) {
  return facet::test::runFacet(args);
}

class MeasureCli : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("facet_measure_cli_" + std::to_string(::getpid()));
    fs::create_directories(dir_);
    facet::scene::SceneSpec spec;
    spec.size = {200, 120};
    spec.background = 50;
    spec.blurSigma = 0.9;
    spec.noiseSigma = 1.0;
    spec.subrows = 64;
    facet::scene::Scene s(spec);
    // A light plate whose top edge is the line y = 80.3, with a slot 6.4 px wide at x = 60.2 and
    // two light discs above it.
    s.addPolygon({{-10, 80.3}, {210, 80.3}, {210, 130}, {-10, 130}}, 180);
    s.addPolygon({{60.2, 85}, {66.6, 85}, {66.6, 130}, {60.2, 130}}, 50);
    s.addDisc({40.4, 30.2}, 9.5, 180);
    s.addDisc({140.1, 35.7}, 14.2, 180);
    image_ = (dir_ / "plate.png").string();
    s.write(image_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  fs::path dir_;
  std::string image_;
};

TEST_F(MeasureCli, CaliperPrintsEdgesAndPairs) {
  // Horizontal caliper across the slot, at y = 100: falling edge at 60.2, rising at 66.6.
  const CliRun r = facet("caliper --image " + image_ +
                         " --rect 63,100,30,10,0 --pairs --polarity falling --json");
  ASSERT_EQ(r.exitCode, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  ASSERT_EQ(j.at("edges").size(), 1u);  // the falling one
  EXPECT_NEAR(j["edges"][0].at("x").get<double>(), 60.2, 0.05);
  EXPECT_NEAR(j["edges"][0].at("y").get<double>(), 100, 1e-9);
  EXPECT_NEAR(j["edges"][0].at("position").get<double>(), 60.2 - 63, 0.05);
  EXPECT_LT(j["edges"][0].at("amplitude").get<double>(), -100);
  EXPECT_FALSE(j["edges"][0].at("clipped").get<bool>());  // nothing near it at 0 or 255
  ASSERT_EQ(j.at("pairs").size(), 1u);
  EXPECT_NEAR(j["pairs"][0].at("width").get<double>(), 6.4, 0.05);
  EXPECT_NEAR(j["pairs"][0].at("x").get<double>(), 63.4, 0.05);
  EXPECT_FALSE(j.at("partial").get<bool>());
  EXPECT_GE(j.at("time_ms").get<double>(), 0.0);

  // Vertical caliper at x = 20 pointing up (angle 90): the plate's edge falls going up.
  const CliRun up = facet("caliper --image " + image_ + " --rect 20,80,20,6,90 --json");
  ASSERT_EQ(up.exitCode, 0) << up.err;
  const auto ju = nlohmann::json::parse(up.out);
  ASSERT_EQ(ju.at("edges").size(), 1u);
  EXPECT_NEAR(ju["edges"][0].at("y").get<double>(), 80.3, 0.05);
  EXPECT_NEAR(ju["edges"][0].at("position").get<double>(), -0.3, 0.05);
  EXPECT_LT(ju["edges"][0].at("amplitude").get<double>(), 0);
}

TEST_F(MeasureCli, LinePrintsTheSegmentAngleAndStraightness) {
  const CliRun r = facet("line --image " + image_ + " --rect 120,80,100,12,0 --json");
  ASSERT_EQ(r.exitCode, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_NEAR(j.at("line").at("y1").get<double>(), 80.3, 0.03);
  EXPECT_NEAR(j.at("line").at("y2").get<double>(), 80.3, 0.03);
  EXPECT_LT(j["line"].at("x1").get<double>(), j["line"].at("x2").get<double>());
  EXPECT_NEAR(j["line"].at("angle").get<double>(), 0.0, 0.02);
  EXPECT_LT(j.at("rms").get<double>(), 0.05);
  EXPECT_LT(j.at("straightness").get<double>(), 0.2);
  EXPECT_GT(j.at("points").get<int>(), 45);  // one per 2 px
}

TEST_F(MeasureCli, BlobPrintsEachBlob) {
  const CliRun r = facet("blob --image " + image_ + " --roi 0,0,200,70 --min-area 50 --json");
  ASSERT_EQ(r.exitCode, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  ASSERT_EQ(j.at("blobs").size(), 2u);
  const auto& big = j["blobs"][0];
  EXPECT_NEAR(big.at("x").get<double>(), 140.1, 0.05);
  EXPECT_NEAR(big.at("y").get<double>(), 35.7, 0.05);
  EXPECT_NEAR(big.at("area").get<double>(), M_PI * 14.2 * 14.2, 0.01 * M_PI * 14.2 * 14.2);
  ASSERT_EQ(big.at("bbox").size(), 4u);
  EXPECT_NEAR(big["bbox"][2].get<int>(), 28, 2);
  EXPECT_GE(j.at("time_ms").get<double>(), 0.0);
  // The small disc falls under a larger minimum area.
  const CliRun big1 = facet("blob --image " + image_ + " --roi 0,0,200,70 --min-area 400 --json");
  ASSERT_EQ(big1.exitCode, 0) << big1.err;
  EXPECT_EQ(nlohmann::json::parse(big1.out).at("blobs").size(), 1u);
  // The slot, a dark blob 6.4 px wide and 30 long in this region, is not round.
  const std::string slot = "blob --image " + image_ + " --roi 50,90,30,30 --polarity dark";
  const CliRun any = facet(slot + " --json");
  ASSERT_EQ(any.exitCode, 0) << any.err;
  const auto a = nlohmann::json::parse(any.out);
  ASSERT_EQ(a.at("blobs").size(), 1u) << any.out;
  EXPECT_LT(a["blobs"][0]["ellipse"]["minor_radius"].get<double>(),
            0.5 * a["blobs"][0]["ellipse"]["major_radius"].get<double>());
  const CliRun round = facet(slot + " --min-roundness 0.5 --json");
  EXPECT_EQ(round.exitCode, 2) << round.out;
  const CliRun bad = facet(slot + " --min-roundness 2");
  EXPECT_EQ(bad.exitCode, 1);
  EXPECT_NE(bad.err.find("--min-roundness"), std::string::npos) << bad.err;
}

TEST_F(MeasureCli, MeasurementFailuresAreJsonErrorsWithTheirCause) {
  auto cause = [&](const std::string& args) {
    const CliRun r = facet(args + " --json");
    EXPECT_EQ(r.exitCode, 2) << args << ": " << r.err;
    return nlohmann::json::parse(r.out).at("error").at("cause").get<std::string>();
  };
  EXPECT_EQ(cause("caliper --image " + image_ + " --rect 900,900,20,6,0"), "outside_image");
  EXPECT_EQ(cause("caliper --image " + image_ + " --rect 20,100,0,6,0"), "zero_size");
  EXPECT_EQ(cause("caliper --image " + image_ + " --rect 20,50,20,6,0"), "no_contrast");
  EXPECT_EQ(cause("caliper --image " + image_ + " --rect 20,80,20,6,90 --polarity rising"),
            "no_edge");
  EXPECT_EQ(cause("line --image " + image_ + " --rect 20,50,30,6,0"), "no_contrast");
  EXPECT_EQ(cause("blob --image " + image_ + " --roi 0,0,200,70 --min-area 5000"), "no_blob");
  EXPECT_EQ(cause("blob --image " + image_ + " --roi 500,500,10,10"), "outside_image");
  // Partly outside: measured inside and flagged.
  const CliRun part = facet("caliper --image " + image_ + " --rect 20,105,60,6,90 --json");
  ASSERT_EQ(part.exitCode, 0) << part.err;
  EXPECT_TRUE(nlohmann::json::parse(part.out).at("partial").get<bool>());
}

TEST_F(MeasureCli, BadInputNamesTheFileOrTheOption) {
  const CliRun missing =
      facet("caliper --image " + (dir_ / "nope.png").string() + " --rect 1,2,3,4,5 --json");
  EXPECT_EQ(missing.exitCode, 1);
  EXPECT_NE(missing.err.find("nope.png"), std::string::npos) << missing.err;
  const CliRun rect = facet("caliper --image " + image_ + " --rect 1,2,3");
  EXPECT_EQ(rect.exitCode, 1);
  EXPECT_NE(rect.err.find("--rect"), std::string::npos) << rect.err;
  const CliRun pol = facet("line --image " + image_ + " --rect 1,2,3,4,5 --polarity up");
  EXPECT_EQ(pol.exitCode, 1);
  EXPECT_NE(pol.err.find("--polarity"), std::string::npos) << pol.err;
  const CliRun sel = facet("caliper --image " + image_ + " --rect 1,2,3,4,5 --select best");
  EXPECT_EQ(sel.exitCode, 1);
  EXPECT_NE(sel.err.find("--select"), std::string::npos) << sel.err;
  const CliRun thr = facet("blob --image " + image_ + " --threshold lots");
  EXPECT_EQ(thr.exitCode, 1);
  EXPECT_NE(thr.err.find("--threshold"), std::string::npos) << thr.err;
  const CliRun both = facet("caliper --image " + image_ + " --rect 1,2,3,4,5 --arc 1,2,3,4,5,6");
  EXPECT_EQ(both.exitCode, 1);
  EXPECT_NE(both.err.find("--arc"), std::string::npos) << both.err;
}

}  // namespace
