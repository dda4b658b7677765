// Calibration from rendered views against the renderer's camera.
#include "algorithms/calibration/camera_calibration.hpp"

#include <cmath>

#include <gtest/gtest.h>

#include "tests/calibration/calibration_scenes.hpp"

namespace facet {
namespace {

std::vector<PlateView> renderViews(const BoardSpec& board, const scene::LensCamera& camera, int n,
                                   std::uint64_t seed) {
  std::vector<PlateView> views;
  for (int i = 0; i < n; ++i)
    views.push_back(detectPlate(test::plateScene(board, camera, seed, i).render(), board,
                                "view" + std::to_string(i)));
  return views;
}

void expectCamera(const CameraCalibration& c, const scene::LensCamera& truth) {
  ASSERT_TRUE(c.ok) << c.why;
  EXPECT_LT(c.rmsPx, 0.1);
  EXPECT_NEAR(c.camera.cameraMatrix(0, 0), truth.fx, 0.005 * truth.fx);
  EXPECT_NEAR(c.camera.cameraMatrix(1, 1), truth.fy, 0.005 * truth.fy);
  EXPECT_NEAR(c.camera.cameraMatrix(0, 2), truth.cx, 3.0);
  EXPECT_NEAR(c.camera.cameraMatrix(1, 2), truth.cy, 3.0);
  EXPECT_NEAR(c.camera.distortion.at<double>(0), truth.k1, 0.02);
  // Where it matters: the model maps the field like the true camera (within 0.1 px).
  for (double x : {100.0, 640.0, 1180.0})
    for (double y : {100.0, 512.0, 920.0}) {
      const cv::Point2d n = c.camera.undistort({x, y});
      const cv::Point2d back = truth.project({n.x, n.y, 1.0});
      EXPECT_LT(cv::norm(back - cv::Point2d(x, y)), 0.25) << x << "," << y;
    }
}

TEST(CameraCalibration, ChessboardViewsGiveTheRenderedCamera) {
  const auto camera = test::testCamera();
  const auto c = calibrateCamera(test::chessboard(), camera.size,
                                 renderViews(test::chessboard(), camera, 10, 21));
  expectCamera(c, camera);
  EXPECT_GT(c.coverage, 0.3);
}

TEST(CameraCalibration, CircleGridViewsGiveTheRenderedCamera) {
  const auto camera = test::testCamera();
  const auto c = calibrateCamera(test::circleGrid(), camera.size,
                                 renderViews(test::circleGrid(), camera, 10, 22));
  expectCamera(c, camera);
}

TEST(CameraCalibration, RefusesTooFewViewsNamingTheCount) {
  const auto camera = test::testCamera();
  const auto c = calibrateCamera(test::chessboard(), camera.size,
                                 renderViews(test::chessboard(), camera, 5, 23));
  EXPECT_FALSE(c.ok);
  EXPECT_NE(c.why.find("5 of 5"), std::string::npos) << c.why;
  EXPECT_NE(c.why.find("at least 8"), std::string::npos) << c.why;
}

TEST(CameraCalibration, RefusesAnRmsAboveTheLimit) {
  const auto camera = test::testCamera();
  CalibrationOptions strict;
  strict.maxRmsPx = 1e-6;
  const auto c = calibrateCamera(test::chessboard(), camera.size,
                                 renderViews(test::chessboard(), camera, 8, 24), strict);
  EXPECT_FALSE(c.ok);
  EXPECT_NE(c.why.find("RMS"), std::string::npos) << c.why;
}

}  // namespace
}  // namespace facet
