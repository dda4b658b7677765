// `facet register` end to end: generated images written to disk, the real binary, its JSON.
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "algorithms/registration/register_images.hpp"
#include "tests/registration/textured_scene.hpp"
#include "tests/support/cli/facet_cli.hpp"

namespace {

namespace fs = std::filesystem;

using facet::test::CliRun;
CliRun facet(const std::string& args) {
  return facet::test::runFacet(args);
}

class RegisterCli : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("facet_register_cli_" + std::to_string(::getpid()));
    fs::create_directories(dir_);
    const cv::Mat ref = facet::testing::texturedScene({280, 260}, 41);
    truth_ = facet::testing::similarity(-50.0, 0.8, {139.5, 129.5}, {150, 140});
    ref_ = (dir_ / "ref.png").string();
    image_ = (dir_ / "image.png").string();
    blank_ = (dir_ / "blank.png").string();
    cv::imwrite(ref_, ref);
    cv::imwrite(image_, facet::testing::warp(ref, truth_, {300, 280}));
    cv::imwrite(blank_, cv::Mat(100, 100, CV_8U, cv::Scalar(90)));
  }
  void TearDown() override { fs::remove_all(dir_); }

  fs::path dir_;
  std::string ref_, image_, blank_;
  cv::Matx33d truth_;
};

TEST_F(RegisterCli, PrintsASummaryByDefault) {
  const CliRun r =
      facet("register --ref " + ref_ + " --image " + image_ + " --model similarity --json");
  ASSERT_EQ(r.exitCode, 0) << r.err << r.out;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j.at("H").size(), 9u);
  EXPECT_GT(j.at("inliers").get<int>(), 10);
  EXPECT_FALSE(j.contains("pairs")) << "pairs only with --pairs";
  EXPECT_LT(r.out.size(), 1000u);
}

TEST_F(RegisterCli, PrintsTheTransformAndTheInlierPairsOnRequest) {
  const CliRun r =
      facet("register --ref " + ref_ + " --image " + image_ + " --model similarity --json --pairs");
  ASSERT_EQ(r.exitCode, 0) << r.err << r.out;
  const auto j = nlohmann::json::parse(r.out);
  ASSERT_EQ(j.at("H").size(), 9u);
  cv::Matx33d H;
  for (int k = 0; k < 9; ++k) H(k / 3, k % 3) = j.at("H")[k].get<double>();
  for (const cv::Point2d p : {cv::Point2d(0, 0), cv::Point2d(279, 259)}) {
    const cv::Vec3d a = H * cv::Vec3d(p.x, p.y, 1), b = truth_ * cv::Vec3d(p.x, p.y, 1);
    EXPECT_LT(std::hypot(a[0] / a[2] - b[0] / b[2], a[1] / a[2] - b[1] / b[2]), 1.0);
  }
  EXPECT_GE(j.at("matches").get<int>(), j.at("inliers").get<int>());
  EXPECT_EQ(j.at("pairs").size(), j.at("inliers").get<std::size_t>());
  ASSERT_GT(j.at("pairs").size(), 10u);
  for (const auto& pair : j.at("pairs")) {
    ASSERT_EQ(pair.size(), 4u);
    const cv::Vec3d t = truth_ * cv::Vec3d(pair[0].get<double>(), pair[1].get<double>(), 1);
    EXPECT_LT(std::hypot(t[0] - pair[2].get<double>(), t[1] - pair[3].get<double>()), 3.0);
  }
  EXPECT_GT(j.at("time_ms").get<double>(), 0.0);
  // Pairs over the whole view: the overlap is placed to a few hundredths of a pixel.
  EXPECT_GT(j.at("overlap_uncertainty_px").get<double>(), 0.0);
  EXPECT_LT(j.at("overlap_uncertainty_px").get<double>(), 0.1);
  // An easy pair: the fast stage stands on its own.
  EXPECT_EQ(j.at("stage").get<std::string>(), "harris");
  EXPECT_FALSE(j.at("escalated").get<bool>());
  EXPECT_GE(j.at("global_inliers").get<int>(), 20);
  EXPECT_EQ(j.at("consensus_rank").get<int>(), 0);
  // The warp-and-re-match passes kept, and how far the last moved H.
  EXPECT_GE(j.at("refine_passes").get<int>(), 1);
  EXPECT_LE(j.at("refine_passes").get<int>(), facet::RegistrationParams{}.refineIterations);
  EXPECT_GE(j.at("refine_last_move_px").get<double>(), 0.0);
}

// A view out of focus: the command says by how much, in the JSON and in words.
TEST_F(RegisterCli, SaysHowMuchMoreBlurredTheImageIs) {
  const CliRun sharp =
      facet("register --ref " + ref_ + " --image " + image_ + " --model similarity --json");
  ASSERT_EQ(sharp.exitCode, 0) << sharp.err << sharp.out;
  EXPECT_EQ(nlohmann::json::parse(sharp.out).at("defocus_px").get<double>(), 0.0);
  cv::Mat blurred = cv::imread(image_, cv::IMREAD_GRAYSCALE);
  cv::GaussianBlur(blurred, blurred, cv::Size(), 2.5, 2.5);
  const std::string path = (dir_ / "blurred.png").string();
  cv::imwrite(path, blurred);
  const CliRun json =
      facet("register --ref " + ref_ + " --image " + path + " --model similarity --json");
  ASSERT_EQ(json.exitCode, 0) << json.err << json.out;
  EXPECT_NEAR(nlohmann::json::parse(json.out).at("defocus_px").get<double>(), 2.5, 0.4);
  const CliRun words = facet("register --ref " + path + " --image " + ref_);
  ASSERT_EQ(words.exitCode, 0) << words.err << words.out;
  EXPECT_NE(words.out.find("the reference is more blurred than the image"), std::string::npos)
      << words.out;
  EXPECT_NE(words.out.find("the part of the reference the image sees is placed within"),
            std::string::npos)
      << words.out;
}

TEST_F(RegisterCli, BlankImageIsAMeasurementFailureWithItsCause) {
  const CliRun r = facet("register --ref " + ref_ + " --image " + blank_ + " --json");
  EXPECT_EQ(r.exitCode, 2);
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j.at("error").at("cause"), "blank_image");
  EXPECT_NE(j.at("error").at("message").get<std::string>().find("blank.png"), std::string::npos);
}

TEST_F(RegisterCli, BadInputNamesTheFileOrTheOption) {
  const CliRun missing =
      facet("register --ref " + (dir_ / "nope.png").string() + " --image " + image_ + " --json");
  EXPECT_EQ(missing.exitCode, 1);
  EXPECT_NE(missing.err.find("nope.png"), std::string::npos) << missing.err;
  const CliRun model = facet("register --ref " + ref_ + " --image " + image_ + " --model rigid");
  EXPECT_EQ(model.exitCode, 1);
  EXPECT_NE(model.err.find("--model"), std::string::npos) << model.err;
}

}  // namespace
