// `facet calibrate` and `facet circle --calibration` end to end, through the real binary, on
// rendered plate images with known camera, plane and holes.
// GCC 12 at -O3 reports a false -Wrestrict inside std::string concatenation here (GCC bug 105329).
#pragma GCC diagnostic ignored "-Wrestrict"
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>

#include "tests/calibration/calibration_scenes.hpp"
#include "tests/support/cli/facet_cli.hpp"

namespace facet {
namespace {

namespace fs = std::filesystem;

class CalibrateCli : public ::testing::Test {
 protected:
  static inline fs::path dir;
  static inline scene::PlanePlacement partPlacement;

  static void SetUpTestSuite() {
    dir = fs::temp_directory_path() / ("facet-calibrate-cli-" + std::to_string(::getpid()));
    fs::create_directories(dir / "views");
    const BoardSpec board = test::chessboard();
    const auto camera = test::testCamera();
    for (int i = 0; i < 10; ++i)
      cv::imwrite((dir / "views" / ("view" + std::to_string(i) + ".png")).string(),
                  test::plateScene(board, camera, 31, i).render());
    // The plate laid where the parts lie, and a part with a 6 mm hole there.
    scene::PlaneScene plate;
    plate.camera = camera;
    plate.placement = scene::lookAtPlane({50, 35}, 260, 12, 40, 3, camera);
    scene::addChessboardPlate(plate, board.cols, board.rows, board.pitchMm);
    plate.noiseSigma = 2;
    cv::imwrite((dir / "plane.png").string(), plate.render());
    partPlacement = plate.placement;
    scene::PlaneScene part = plate;
    part.shapes.clear();
    part.addPolygon({{-10, -10}, {110, -10}, {110, 80}, {-10, 80}}, 210);
    part.addDisc({70, 20}, 3.0, 30);
    cv::imwrite((dir / "part.png").string(), part.render());
    std::ofstream(dir / "part_centre.txt")
        << part.imageOf({70, 20}).x << "," << part.imageOf({70, 20}).y;
  }
  static void TearDownTestSuite() { fs::remove_all(dir); }
};

TEST_F(CalibrateCli, CalibratesWritesTheFileAndMeasuresInTheRightPlane) {
  const auto cal = dir / "station_calibration.yaml";
  const auto run = test::runFacet("calibrate --images " + (dir / "views").string() +
                                  " --board chessboard:11x8:10 --plane " +
                                  (dir / "plane.png").string() + " --out " + cal.string() +
                                  " --report " + (dir / "report.html").string() + " --json");
  ASSERT_EQ(run.exitCode, 0) << run.err << run.out;
  const auto j = nlohmann::json::parse(run.out);
  EXPECT_LT(j["rms_px"].get<double>(), 0.1);
  EXPECT_NEAR(j["camera_matrix"][0][0].get<double>(), 1500, 10);
  EXPECT_NEAR(j["distortion"][0].get<double>(), -0.22, 0.03);
  EXPECT_EQ(j["image_size"], nlohmann::json({1280, 1024}));
  EXPECT_EQ(j["views"].size(), 10u);
  for (const auto& v : j["views"]) EXPECT_TRUE(v["used"].get<bool>()) << v.dump();
  ASSERT_TRUE(j.contains("plane"));
  EXPECT_NEAR(j["plane"]["translation_mm"][2].get<double>(), partPlacement.translationMm[2], 1.0);
  EXPECT_TRUE(fs::exists(cal));
  std::ifstream report(dir / "report.html");
  const std::string html((std::istreambuf_iterator<char>(report)), {});
  EXPECT_NE(html.find("<svg"), std::string::npos);
  EXPECT_NE(html.find("view9.png"), std::string::npos);

  std::ifstream centreFile(dir / "part_centre.txt");
  std::string centre;
  centreFile >> centre;
  const auto circle =
      test::runFacet("circle --image " + (dir / "part.png").string() + " --center " + centre +
                     " --radius 20 --width 6 --calibration " + cal.string() + " --json");
  ASSERT_EQ(circle.exitCode, 0) << circle.err << circle.out;
  const auto c = nlohmann::json::parse(circle.out);
  ASSERT_TRUE(c.contains("world")) << circle.out;
  EXPECT_NEAR(c["world"]["x_mm"].get<double>(), 70, 0.02);
  EXPECT_NEAR(c["world"]["y_mm"].get<double>(), 20, 0.02);
  EXPECT_NEAR(c["world"]["diameter_mm"].get<double>(), 6, 0.01);
  // The rim's roundness in the plane: the spread of its points there, a few times their RMS.
  EXPECT_GT(c["world"]["roundness_mm"].get<double>(), 2 * c["world"]["rms_mm"].get<double>())
      << c.dump();
  EXPECT_LT(c["world"]["roundness_mm"].get<double>(), 6 * c["world"]["rms_mm"].get<double>())
      << c.dump();
  EXPECT_EQ(c["world"]["calibration"], "lens model + plane");
}

TEST_F(CalibrateCli, CalibratesFromACharucoPlatePartlyOutsideSomeViewsWithThePlaneFromOne) {
  const BoardSpec board = test::charucoBoard();
  const auto camera = test::testCamera();
  const auto views = dir / "charuco";
  fs::create_directories(views);
  for (int i = 0; i < 6; ++i)
    cv::imwrite((views / ("view" + std::to_string(i) + ".png")).string(),
                test::plateScene(board, camera, 37, i).render());
  // A close view with the plate's top-left part beyond the image.
  scene::PlaneScene close;
  close.camera = camera;
  close.placement = scene::lookAtPlane({85, 60}, 180, 25, 30, -6, camera);
  scene::addCharucoPlate(close, board.cols + 1, board.rows + 1, board.pitchMm, board.markerMm,
                         board.dictionary);
  close.noiseSigma = 2;
  cv::imwrite((views / "close.png").string(), close.render());
  // The plane from a view that shows part of the plate, too.
  scene::PlaneScene plane = close;
  plane.placement = scene::lookAtPlane({70, 50}, 200, 10, 60, 4, camera);
  cv::imwrite((dir / "charuco_plane.png").string(), plane.render());

  const auto cal = dir / "charuco_calibration.yaml";
  const auto run = test::runFacet(
      "calibrate --images " + views.string() + " --board " + board.text() + " --min-views 6" +
      " --plane " + (dir / "charuco_plane.png").string() + " --out " + cal.string() + " --json");
  ASSERT_EQ(run.exitCode, 0) << run.err << run.out;
  const auto j = nlohmann::json::parse(run.out);
  EXPECT_LT(j["rms_px"].get<double>(), 0.1);
  EXPECT_NEAR(j["camera_matrix"][0][0].get<double>(), 1500, 10);
  EXPECT_NEAR(j["distortion"][0].get<double>(), -0.22, 0.03);
  ASSERT_EQ(j["views"].size(), 7u);
  for (const auto& v : j["views"]) {
    EXPECT_TRUE(v["used"].get<bool>()) << v.dump();
    if (v["file"] == "close.png") {
      EXPECT_LT(v["points"].get<int>(), 88) << v.dump();
      EXPECT_NE(v["note"].get<std::string>().find("of 88 corners"), std::string::npos) << v.dump();
    } else {
      EXPECT_EQ(v["points"].get<int>(), 88) << v.dump();
    }
  }
  ASSERT_TRUE(j.contains("plane"));
  EXPECT_NEAR(j["plane"]["translation_mm"][2].get<double>(), plane.placement.translationMm[2], 1.0);
}

// The example station's calibration file is what `facet calibrate` makes of the plate images
// shipped beside it (recipes/README.md): nobody edited it by hand, and the command still reads
// those plates the same way.
TEST(ExampleStationCalibration, IsWhatFacetCalibrateMakesOfTheShippedPlates) {
  const fs::path out = fs::temp_directory_path() /
                       ("facet-example-calibration-" + std::to_string(::getpid()) + ".yaml");
  const auto run = test::runFacet(
      "calibrate --images recipes/calibration_plates/views --board chessboard:11x8:2 --plane "
      "recipes/calibration_plates/plane.png --out " +
      out.string() + " --json");
  ASSERT_EQ(run.exitCode, 0) << run.err << run.out;
  const auto j = nlohmann::json::parse(run.out);
  for (const auto& v : j["views"]) EXPECT_TRUE(v["used"].get<bool>()) << v.dump();
  EXPECT_GE(j["coverage"].get<double>(), 0.6);
  // The file's values, as written (YAML, read as text: the numbers follow their keys).
  std::ifstream in("recipes/calibration.yaml");
  const std::string shipped((std::istreambuf_iterator<char>(in)), {});
  const auto number = [&](const std::string& key) {
    const auto at = shipped.find(key);
    if (at == std::string::npos) return std::nan("");
    return std::stod(shipped.substr(shipped.find_first_of("-0123456789", at + key.size())));
  };
  const double mmPerPixel = number("\nmm_per_pixel:");
  EXPECT_NEAR(j["plane"]["mm_per_px"].get<double>(), mmPerPixel, 1e-9);
  EXPECT_NEAR(mmPerPixel, 0.05, 1e-4);  // the scale the demo parts were recorded at
  EXPECT_NEAR(j["rms_px"].get<double>(), number("\nrms_px:"), 1e-9);
  EXPECT_NEAR(j["distortion"][0].get<double>(), number("\ndistortion: ["), 1e-9);
  fs::remove(out);
}

TEST_F(CalibrateCli, RefusesTooFewViewsNamingEveryUnusedImage) {
  fs::create_directories(dir / "few");
  for (int i = 0; i < 5; ++i)
    fs::copy_file(dir / "views" / ("view" + std::to_string(i) + ".png"),
                  dir / "few" / ("v" + std::to_string(i) + ".png"),
                  fs::copy_options::overwrite_existing);
  std::ofstream(dir / "few" / "broken.png") << "not an image";
  const auto run = test::runFacet("calibrate --images " + (dir / "few").string() +
                                  " --board chessboard:11x8:10 --out " +
                                  (dir / "few.yaml").string() + " --json");
  EXPECT_EQ(run.exitCode, 2) << run.err << run.out;
  const auto j = nlohmann::json::parse(run.out);
  EXPECT_NE(j["error"]["message"].get<std::string>().find("at least 8"), std::string::npos)
      << run.out;
  bool brokenNamed = false;
  for (const auto& v : j["views"])
    if (v["file"] == "broken.png")
      brokenNamed = !v["used"].get<bool>() && !v["why"].get<std::string>().empty();
  EXPECT_TRUE(brokenNamed) << run.out;
  EXPECT_FALSE(fs::exists(dir / "few.yaml"));
}

TEST_F(CalibrateCli, WrongBoardSpecIsRefusedWithReasons) {
  // Four views are enough to be refused; OpenCV's search for a board that is not there is the
  // slow part (minutes for ten views under ASan).
  fs::create_directories(dir / "four_views");
  for (int i = 0; i < 4; ++i)
    fs::copy_file(dir / "views" / ("view" + std::to_string(i) + ".png"),
                  dir / "four_views" / ("view" + std::to_string(i) + ".png"),
                  fs::copy_options::overwrite_existing);
  const auto run =
      test::runFacet("calibrate --images " + (dir / "four_views").string() +
                     " --board chessboard:8x5:10 --out " + (dir / "wrong.yaml").string());
  EXPECT_NE(run.exitCode, 0) << run.out;
  // Views are named with their reason; not every view of a too-small spec is recognised as a
  // larger plate (some read as "no chessboard found"), so the test asks for the reason, not for
  // a particular view.
  EXPECT_NE(run.err.find("view"), std::string::npos) << run.err;
  EXPECT_NE(run.err.find("is the board spec right?"), std::string::npos) << run.err;
  const auto bad =
      test::runFacet("calibrate --images " + (dir / "views").string() +
                     " --board chessboard:10x8:10 --out " + (dir / "wrong.yaml").string());
  EXPECT_EQ(bad.exitCode, 1);
  EXPECT_NE(bad.err.find("one count must be even"), std::string::npos) << bad.err;
}

TEST_F(CalibrateCli, ImagesOfDifferentSizesAreRefusedNamingBoth) {
  fs::create_directories(dir / "mixed");
  fs::copy_file(dir / "views" / "view0.png", dir / "mixed" / "a.png",
                fs::copy_options::overwrite_existing);
  cv::imwrite((dir / "mixed" / "b.png").string(), cv::Mat(480, 640, CV_8U, cv::Scalar(128)));
  const auto run = test::runFacet("calibrate --images " + (dir / "mixed").string() +
                                  " --board chessboard:11x8:10 --out " + (dir / "m.yaml").string());
  EXPECT_EQ(run.exitCode, 1);
  EXPECT_NE(run.err.find("640x480"), std::string::npos) << run.err;
  EXPECT_NE(run.err.find("1280x1024"), std::string::npos) << run.err;
}

TEST_F(CalibrateCli, CircleRefusesABrokenOrMismatchedCalibrationFile) {
  std::ofstream(dir / "cut.yaml") << "format: facet-calibration 1\nimage_size: [1280, "
                                     "1024]\ncamera_matrix: [[1500, 0, 640], [0, 1500";
  const auto cut = test::runFacet("circle --image " + (dir / "part.png").string() +
                                  " --center 600,500 --radius 20 --calibration " +
                                  (dir / "cut.yaml").string() + " --json");
  EXPECT_EQ(cut.exitCode, 1);
  EXPECT_NE(cut.err.find((dir / "cut.yaml").string() + ":"), std::string::npos) << cut.err;
  std::ofstream(dir / "small.yaml") << "format: facet-calibration 1\nimage_size: [640, 480]\n"
                                       "camera_matrix: [[800, 0, 320], [0, 800, 240], [0, 0, 1]]\n"
                                       "distortion: [0, 0, 0, 0]\nmm_per_pixel: 0.1\n";
  const auto small = test::runFacet("circle --image " + (dir / "part.png").string() +
                                    " --center 600,500 --radius 20 --calibration " +
                                    (dir / "small.yaml").string());
  EXPECT_EQ(small.exitCode, 1);
  EXPECT_NE(small.err.find("640x480"), std::string::npos) << small.err;
  EXPECT_NE(small.err.find("1280x1024"), std::string::npos) << small.err;
}

}  // namespace
}  // namespace facet
