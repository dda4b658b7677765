// `facet circle` end to end: a generated scene written to disk, the real binary, its JSON.
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

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

class CircleCli : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("facet_circle_cli_" + std::to_string(::getpid()));
    fs::create_directories(dir_);
    facet::scene::Scene s(sceneSpec());
    s.addDisc(centre_, 40.3, 170);
    image_ = (dir_ / "disc.png").string();
    s.write(image_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  // The scenes' 160x140 view: a dark background, blur 1 px, noise 2.
  static facet::scene::SceneSpec sceneSpec() {
    facet::scene::SceneSpec spec;
    spec.size = {160, 140};
    spec.background = 60;
    spec.blurSigma = 1.0;
    spec.noiseSigma = 2.0;
    spec.subrows = 64;
    return spec;
  }

  fs::path dir_;
  std::string image_;
  cv::Point2d centre_{80.4, 69.7};
};

TEST_F(CircleCli, PrintsOneJsonObjectWithTheCircle) {
  const CliRun r = facet("circle --image " + image_ +
                         " --center 81,69 --radius 40 --polarity light_to_dark --json");
  ASSERT_EQ(r.exitCode, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_NEAR(j.at("x").get<double>(), centre_.x, 0.05);
  EXPECT_NEAR(j.at("y").get<double>(), centre_.y, 0.05);
  EXPECT_NEAR(j.at("radius").get<double>(), 40.3, 0.05);
  EXPECT_GT(j.at("inliers").get<int>(), 100);
  EXPECT_GT(j.at("coverage_deg").get<double>(), 350.0);
  EXPECT_LT(j.at("rms").get<double>(), 0.2);
  EXPECT_GE(j.at("roundness").get<double>(), 0.0);
  EXPECT_GE(j.at("time_ms").get<double>(), 0.0);
  EXPECT_TRUE(j.at("grey_refined").get<bool>());
  EXPECT_NEAR(j.at("blur").get<double>(), 1.0, 0.3);  // the scene's PSF sigma, plus pixel size
  EXPECT_FALSE(j.at("elliptic").get<bool>());
  EXPECT_FALSE(j.contains("ellipse"));
  EXPECT_EQ(j.at("clipped_share").get<double>(), 0.0);  // nothing near the rim at 0 or 255
}

// A disc on an overexposed background (the sensor reads 255 where its light is 1.6 times that):
// measured with the clip in the model, and the share of clipped pixels reported.
TEST_F(CircleCli, AClippedRimIsMeasuredAndReportsTheClippedShare) {
  facet::scene::SceneSpec spec = sceneSpec();
  spec.background = 400;
  facet::scene::Scene s(spec);
  s.addDisc(centre_, 40.3, 30);
  const std::string image = (dir_ / "backlit.png").string();
  s.write(image);
  const std::string args = "circle --image " + image + " --center 81,69 --radius 40";
  const CliRun r = facet(args + " --json");
  ASSERT_EQ(r.exitCode, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_NEAR(j.at("radius").get<double>(), 40.3, 0.06);
  EXPECT_GT(j.at("clipped_share").get<double>(), 0.2);
  const CliRun text = facet(args);
  ASSERT_EQ(text.exitCode, 0) << text.err;
  EXPECT_NE(text.out.find("fitted as clipped"), std::string::npos) << text.out;
}

TEST_F(CircleCli, AnEllipticRimReportsItsAxes) {
  // A disc seen at a tilt: an ellipse with semi-axes 40 and 36 px, the major axis 30 degrees
  // counter-clockwise on screen.
  facet::scene::Scene s(sceneSpec());
  std::vector<cv::Point2d> outline;
  const double t = -30.0 * CV_PI / 180.0;  // y down: counter-clockwise on screen is negative
  for (int i = 0; i < 720; ++i) {
    const double a = 2 * CV_PI * i / 720, u = 40.0 * std::cos(a), v = 36.0 * std::sin(a);
    outline.push_back({centre_.x + u * std::cos(t) - v * std::sin(t),
                       centre_.y + u * std::sin(t) + v * std::cos(t)});
  }
  s.addPolygon(outline, 170);
  const std::string image = (dir_ / "ellipse.png").string();
  s.write(image);
  const CliRun r = facet("circle --image " + image +
                         " --center 81,69 --radius 38 --polarity light_to_dark --json");
  ASSERT_EQ(r.exitCode, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_TRUE(j.at("elliptic").get<bool>());
  EXPECT_NEAR(j.at("x").get<double>(), centre_.x, 0.05);
  EXPECT_NEAR(j.at("y").get<double>(), centre_.y, 0.05);
  EXPECT_NEAR(j.at("radius").get<double>(), std::sqrt(40.0 * 36.0), 0.05);
  EXPECT_NEAR(j.at("ellipse").at("major").get<double>(), 80.0, 0.1);
  EXPECT_NEAR(j.at("ellipse").at("minor").get<double>(), 72.0, 0.1);
  EXPECT_NEAR(j.at("ellipse").at("angle").get<double>(), 30.0, 0.5);
  // The text form says so too.
  const CliRun text =
      facet("circle --image " + image + " --center 81,69 --radius 38 --polarity light_to_dark");
  ASSERT_EQ(text.exitCode, 0) << text.err;
  EXPECT_NE(text.out.find("the rim is an ellipse"), std::string::npos) << text.out;
}

TEST_F(CircleCli, MeasurementFailureIsAJsonErrorWithItsCause) {
  // The disc is light inside: asking for a dark-to-light rim finds nothing.
  const CliRun r = facet("circle --image " + image_ +
                         " --center 81,69 --radius 40 --width 3 --polarity dark_to_light --json");
  EXPECT_EQ(r.exitCode, 2);
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j.at("error").at("cause"), "too_few_points");
  EXPECT_NE(j.at("error").at("message").get<std::string>().find("disc.png"), std::string::npos);

  const CliRun outside = facet("circle --image " + image_ + " --center 900,900 --radius 20 --json");
  EXPECT_EQ(outside.exitCode, 2);
  EXPECT_EQ(nlohmann::json::parse(outside.out).at("error").at("cause"), "annulus_outside_image");
}

TEST_F(CircleCli, BadInputNamesTheFileOrTheOption) {
  const CliRun missing = facet("circle --image " + (dir_ / "nope.png").string() +
                               " --center 81,69 --radius 40 --json");
  EXPECT_EQ(missing.exitCode, 1);
  EXPECT_NE(missing.err.find("nope.png"), std::string::npos) << missing.err;

  const fs::path corrupt = dir_ / "corrupt.png";
  std::ofstream(corrupt) << "not a png";
  const CliRun bad = facet("circle --image " + corrupt.string() + " --center 81,69 --radius 40");
  EXPECT_EQ(bad.exitCode, 1);
  EXPECT_NE(bad.err.find("corrupt.png"), std::string::npos) << bad.err;

  const CliRun zero = facet("circle --image " + image_ + " --center 81,69 --radius 0 --json");
  EXPECT_EQ(zero.exitCode, 1);
  EXPECT_NE(zero.err.find("radius"), std::string::npos) << zero.err;

  const CliRun centre = facet("circle --image " + image_ + " --center 81 --radius 40");
  EXPECT_EQ(centre.exitCode, 1);
  EXPECT_NE(centre.err.find("--center"), std::string::npos) << centre.err;

  const CliRun polarity =
      facet("circle --image " + image_ + " --center 81,69 --radius 40 --polarity up");
  EXPECT_EQ(polarity.exitCode, 1);
  EXPECT_NE(polarity.err.find("--polarity"), std::string::npos) << polarity.err;
}

}  // namespace
