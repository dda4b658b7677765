// `facet caliper`, `facet line` and `facet blob` with `--calibration`, end to end through the real
// binary: a part of known size in millimetres, seen through a distorting lens on a tilted plane,
// measured in that plane. The calibration file is written from the renderer's own camera and
// plane, so that these tests measure the commands, not a calibration.
// GCC 12 at -O3 reports a false -Wrestrict inside std::string concatenation here (GCC bug 105329).
#pragma GCC diagnostic ignored "-Wrestrict"
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>

#include "algorithms/calibration/world_mapping.hpp"
#include "config/calibration_file.hpp"
#include "tests/calibration/calibration_scenes.hpp"
#include "tests/support/cli/facet_cli.hpp"

namespace facet {
namespace {

namespace fs = std::filesystem;

// The part, mm in the plane: a light plate with dark bars 4 and 20 mm wide (x 20-24, 40-60), a dark
// disc of radius 8 mm at (90, 20), and a dark field whose top side is a straight edge through (60,
// 50) turned 10 degrees counter-clockwise (the plane's y runs down the image as pixels do).
constexpr double kBarWidth = 4.0, kDiscRadius = 8.0, kEdgeAngle = 10.0;
const cv::Point2d kDisc(90, 20), kEdgeThrough(60, 50);

double edgeY(double x) {
  return kEdgeThrough.y - std::tan(kEdgeAngle * CV_PI / 180) * (x - 60);
}

std::string csv(std::initializer_list<double> values) {
  std::ostringstream s;
  s.precision(10);
  const char* sep = "";
  for (double v : values) s << sep << v, sep = ",";
  return s.str();
}

// The renderer's own camera and plane as a calibration (the commands, not a calibration, under
// test).
config::CalibrationData truthOf(const scene::PlaneScene& scene) {
  config::CalibrationData truth;
  truth.camera = CameraModel{scene.camera.matrix(), scene.camera.distortion(), scene.camera.size};
  truth.plane = PlanePose{scene.placement.rotation, scene.placement.translationMm, 0.0};
  return truth;
}

class MeasureInPlaneCli : public ::testing::Test {
 protected:
  static inline fs::path dir;
  static inline scene::PlaneScene part;

  static void SetUpTestSuite() {
    dir = fs::temp_directory_path() / ("facet-measure-plane-cli-" + std::to_string(::getpid()));
    fs::create_directories(dir);
    part.camera = test::testCamera();
    part.placement = scene::lookAtPlane({50, 35}, 260, 25, 40, 3, part.camera);
    part.addPolygon({{-10, -10}, {110, -10}, {110, 80}, {-10, 80}}, 210);
    part.addPolygon({{20, 0}, {20 + kBarWidth, 0}, {20 + kBarWidth, 30}, {20, 30}}, 40);
    part.addPolygon({{40, 5}, {60, 5}, {60, 30}, {40, 30}}, 40);
    part.addDisc(kDisc, kDiscRadius, 40);
    part.addPolygon({{40, edgeY(40)}, {80, edgeY(80)}, {80, 75}, {40, 75}}, 40);
    part.lensBlurSigma = 0.7;
    part.noiseSigma = 2;
    cv::imwrite((dir / "part.png").string(), part.render());

    std::ofstream(dir / "lens_plane.yaml")
        << config::calibrationFileText(truthOf(part), "test truth");
    std::ofstream(dir / "scale.yaml") << "format: facet-calibration 1\nmm_per_pixel: 0.1\n";
    std::ofstream(dir / "small.yaml")
        << "format: facet-calibration 1\nimage_size: [640, 480]\n"
           "camera_matrix: [[800, 0, 320], [0, 800, 240], [0, 0, 1]]\n"
           "distortion: [0, 0, 0, 0]\nmm_per_pixel: 0.1\n";
  }
  static void TearDownTestSuite() { fs::remove_all(dir); }

  // "cx,cy,length,width,angle" of a rectangle centred on the image of `centreMm` whose axis is
  // the image of the plane direction `dirMm` there; its length covers `halfLengthMm` either side.
  static std::string rectAlong(cv::Point2d centreMm, cv::Point2d dirMm, double halfLengthMm,
                               double widthPx) {
    const cv::Point2d c = part.imageOf(centreMm);
    const cv::Point2d a = part.imageOf(centreMm + dirMm * halfLengthMm);
    const cv::Point2d d = a - c;
    const double angle = std::atan2(-d.y, d.x) * 180 / CV_PI;
    return csv({c.x, c.y, 2 * cv::norm(d), widthPx, angle});
  }

  static nlohmann::json run(const std::string& args) {
    const auto r = test::runFacet(args + " --json");
    EXPECT_EQ(r.exitCode, 0) << args << "\n" << r.err << r.out;
    return r.exitCode == 0 ? nlohmann::json::parse(r.out) : nlohmann::json::object();
  }
};

TEST_F(MeasureInPlaneCli, CaliperGivesTheBarsWidthAndPlaceInMillimetres) {
  const std::string rect = rectAlong({22, 15}, {1, 0}, 7, 20);
  const auto j =
      run("caliper --image " + (dir / "part.png").string() + " --rect " + rect +
          " --pairs --polarity falling --calibration " + (dir / "lens_plane.yaml").string());
  ASSERT_EQ(j["pairs"].size(), 1u) << j.dump();
  const auto& pair = j["pairs"][0];
  EXPECT_NEAR(pair["width_mm"].get<double>(), kBarWidth, 0.01) << pair.dump();
  EXPECT_NEAR(pair["position_mm"].get<double>(), 0.0, 0.01) << pair.dump();
  EXPECT_NEAR(pair["x_mm"].get<double>(), 22.0, 0.02) << pair.dump();
  EXPECT_NEAR(pair["y_mm"].get<double>(), 15.0, 0.05) << pair.dump();
  EXPECT_NEAR(pair["first"]["position_mm"].get<double>(), -kBarWidth / 2, 0.01) << pair.dump();
  EXPECT_NEAR(pair["first"]["x_mm"].get<double>(), 20.0, 0.01) << pair.dump();
  EXPECT_EQ(j["calibration"], "lens model + plane");
  // The width in pixels times the plane's mean scale is not the width: the view is tilted.
  const double meanScale = 7.0 / (cv::norm(part.imageOf({29, 15}) - part.imageOf({22, 15})));
  EXPECT_GT(std::abs(pair["width"].get<double>() * meanScale - kBarWidth), 0.02) << pair.dump();
}

// A wide bar's middle is halfway between its edges in the plane; the image's halfway point is
// not, on a tilted view (0.10 mm off here).
TEST_F(MeasureInPlaneCli, CaliperGivesAWideBarsMiddleInThePlane) {
  const auto j =
      run("caliper --image " + (dir / "part.png").string() + " --rect " +
          rectAlong({50, 17}, {1, 0}, 16, 20) + " --pairs --polarity falling --calibration " +
          (dir / "lens_plane.yaml").string());
  ASSERT_EQ(j["pairs"].size(), 1u) << j.dump();
  const auto& pair = j["pairs"][0];
  EXPECT_NEAR(pair["width_mm"].get<double>(), 20.0, 0.01) << pair.dump();
  EXPECT_NEAR(pair["position_mm"].get<double>(), 0.0, 0.01) << pair.dump();
  EXPECT_NEAR(pair["x_mm"].get<double>(), 50.0, 0.01) << pair.dump();
  EXPECT_NEAR(pair["y_mm"].get<double>(), 17.0, 0.05) << pair.dump();
}

TEST_F(MeasureInPlaneCli, LineGivesTheEdgesAngleAndPlaceInThePlane) {
  const cv::Point2d along(std::cos(kEdgeAngle * CV_PI / 180), -std::sin(kEdgeAngle * CV_PI / 180));
  const std::string rect = rectAlong(kEdgeThrough, along, 15, 24);
  const auto j = run("line --image " + (dir / "part.png").string() + " --rect " + rect +
                     " --calibration " + (dir / "lens_plane.yaml").string());
  ASSERT_TRUE(j.contains("line_mm")) << j.dump();
  const auto& l = j["line_mm"];
  EXPECT_NEAR(l["angle"].get<double>(), kEdgeAngle, 0.02) << j.dump();
  for (const char* end : {"1", "2"}) {
    const double x = l[std::string("x") + end].get<double>();
    const double y = l[std::string("y") + end].get<double>();
    // Distance across the edge (its normal is nearly y).
    EXPECT_NEAR((y - edgeY(x)) * std::cos(kEdgeAngle * CV_PI / 180), 0.0, 0.01) << j.dump();
  }
  EXPECT_NEAR(std::hypot(l["x2"].get<double>() - l["x1"].get<double>(),
                         l["y2"].get<double>() - l["y1"].get<double>()),
              30.0, 1.0)
      << j.dump();
  EXPECT_LT(j["straightness_mm"].get<double>(), 0.02) << j.dump();
  EXPECT_GT(j["straightness_mm"].get<double>(), 0.0) << j.dump();
}

TEST_F(MeasureInPlaneCli, BlobGivesTheDiscsAreaAndCentreInThePlane) {
  const cv::Point2d c = part.imageOf(kDisc);
  const auto j = run("blob --image " + (dir / "part.png").string() + " --roi " +
                     csv({std::round(c.x) - 75, std::round(c.y) - 75, 150, 150}) +
                     " --polarity dark --calibration " + (dir / "lens_plane.yaml").string());
  ASSERT_EQ(j["blobs"].size(), 1u) << j.dump();
  const auto& b = j["blobs"][0];
  EXPECT_NEAR(b["area_mm2"].get<double>(), CV_PI * kDiscRadius * kDiscRadius,
              0.002 * CV_PI * kDiscRadius * kDiscRadius)
      << b.dump();
  // Each pixel counted at its place in the plane: the image centroid mapped is 0.09 mm off.
  EXPECT_NEAR(b["x_mm"].get<double>(), kDisc.x, 0.005) << b.dump();
  EXPECT_NEAR(b["y_mm"].get<double>(), kDisc.y, 0.005) << b.dump();
  EXPECT_NEAR(b["ellipse_mm"]["major_radius"].get<double>(), kDiscRadius, 0.02) << b.dump();
  EXPECT_NEAR(b["ellipse_mm"]["minor_radius"].get<double>(), kDiscRadius, 0.02) << b.dump();
  // In the image the disc is an ellipse.
  EXPECT_GT(b["ellipse"]["major_radius"].get<double>(),
            1.03 * b["ellipse"]["minor_radius"].get<double>())
      << b.dump();
}

// The disc through `facet circle --calibration`: the rim's edge points and grey values fitted in
// the plane (the image's grey fit fits a circle to the disc's ellipse there).
TEST_F(MeasureInPlaneCli, CircleGivesTheDiscInThePlane) {
  const cv::Point2d c = part.imageOf(kDisc);
  const double r = 0.5 * (cv::norm(part.imageOf(kDisc + cv::Point2d(kDiscRadius, 0)) - c) +
                          cv::norm(part.imageOf(kDisc + cv::Point2d(0, kDiscRadius)) - c));
  const auto j =
      run("circle --image " + (dir / "part.png").string() + " --centre " +
          csv({c.x + 0.6, c.y - 0.4}) + " --radius " + csv({r}) + " --width " + csv({0.3 * r}) +
          " --polarity dark_inside --calibration " + (dir / "lens_plane.yaml").string());
  const auto& w = j["world"];
  ASSERT_TRUE(w.is_object()) << j.dump();
  EXPECT_TRUE(w["grey_refined"].get<bool>()) << w.dump();
  EXPECT_FALSE(w["judged_in_plane"].get<bool>()) << w.dump();
  EXPECT_NEAR(w["x_mm"].get<double>(), kDisc.x, 0.002) << w.dump();
  EXPECT_NEAR(w["y_mm"].get<double>(), kDisc.y, 0.002) << w.dump();
  EXPECT_NEAR(w["diameter_mm"].get<double>(), 2 * kDiscRadius, 0.003) << w.dump();
  EXPECT_GT(w["coverage_deg"].get<double>(), 300) << w.dump();
}

// A hole seen at 55 degrees, which the image refuses (its rim is an ellipse of 0.57 : 1 there;
// the edge points' ellipse covers too little of it, a circle keeps less): `facet circle
// --calibration` measures and judges it in the plane and says so; without the calibration the
// command fails as before.
TEST_F(MeasureInPlaneCli, CircleMeasuresInThePlaneAHoleTheImageRefuses) {
  scene::PlaneScene steep;
  steep.camera = test::testCamera();
  steep.placement = scene::lookAtPlane({40, 30}, 250, 55, 20, 10, steep.camera);
  steep.background = 30;
  steep.addPolygon({{-20, -20}, {100, -20}, {100, 80}, {-20, 80}}, 210);
  const cv::Point2d hole(25, 49);
  const double radiusMm = 4;
  steep.addDisc(hole, radiusMm, 40);
  steep.lensBlurSigma = 0.7;
  steep.noiseSigma = 2;
  cv::imwrite((dir / "steep.png").string(), steep.render());
  const config::CalibrationData truth = truthOf(steep);
  std::ofstream(dir / "steep.yaml") << config::calibrationFileText(truth, "test truth");
  const WorldMapping mapping(*truth.camera, *truth.plane);
  const cv::Point2d c = steep.imageOf(hole);
  const double r = radiusMm / mapping.mmPerPixelAt(c);
  const std::string command = "circle --image " + (dir / "steep.png").string() + " --centre " +
                              csv({c.x + 0.6, c.y - 0.4}) + " --radius " + csv({r}) + " --width " +
                              csv({0.35 * r}) + " --polarity dark_inside";
  const auto inImage = test::runFacet(command + " --json");
  ASSERT_NE(inImage.exitCode, 0) << "the view no longer makes the image refuse the hole\n"
                                 << inImage.out;
  const auto j = run(command + " --calibration " + (dir / "steep.yaml").string());
  const auto& w = j["world"];
  ASSERT_TRUE(w.is_object()) << j.dump();
  EXPECT_TRUE(w["judged_in_plane"].get<bool>()) << w.dump();
  EXPECT_NE(j["image_refusal"].get<std::string>(), "") << j.dump();
  EXPECT_NEAR(w["x_mm"].get<double>(), hole.x, 0.002) << w.dump();
  EXPECT_NEAR(w["y_mm"].get<double>(), hole.y, 0.002) << w.dump();
  EXPECT_NEAR(w["diameter_mm"].get<double>(), 2 * radiusMm, 0.003) << w.dump();
  // The image point given is the image of the plane's centre.
  EXPECT_LT(cv::norm(cv::Point2d(j["x"].get<double>(), j["y"].get<double>()) - c), 0.02)
      << j.dump();
}

TEST_F(MeasureInPlaneCli, AScaleOnlyFileMultipliesAndAFileForOtherImagesIsRefused) {
  const std::string caliper = "caliper --image " + (dir / "part.png").string() + " --rect " +
                              rectAlong({22, 15}, {1, 0}, 7, 20) + " --pairs --polarity falling";
  const auto j = run(caliper + " --calibration " + (dir / "scale.yaml").string());
  ASSERT_EQ(j["pairs"].size(), 1u) << j.dump();
  EXPECT_NEAR(j["pairs"][0]["width_mm"].get<double>(), 0.1 * j["pairs"][0]["width"].get<double>(),
              1e-9);
  EXPECT_EQ(j["calibration"], "scale only, no lens model");
  for (const std::string& command :
       {caliper, "line --image " + (dir / "part.png").string() + " --rect 600,500,100,20,0",
        "blob --image " + (dir / "part.png").string()}) {
    const auto small =
        test::runFacet(command + " --calibration " + (dir / "small.yaml").string() + " --json");
    EXPECT_EQ(small.exitCode, 1) << command;
    EXPECT_NE(small.err.find("640x480"), std::string::npos) << command << small.err;
    EXPECT_NE(small.err.find("1280x1024"), std::string::npos) << command << small.err;
  }
}

}  // namespace
}  // namespace facet
