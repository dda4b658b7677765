// Calibration from rendered views against the renderer's camera.
#include "algorithms/calibration/camera_calibration.hpp"

#include <algorithm>
#include <cmath>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "algorithms/calibration/field_coverage.hpp"
#include "tests/calibration/calibration_scenes.hpp"
#include "tests/calibration/model_error.hpp"

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

cv::Mat covered(const CameraCalibration& c, cv::Size size) {
  std::vector<std::vector<cv::Point2d>> outlines;
  for (const auto& v : c.views)
    if (v.used) outlines.push_back(v.points);
  // The convex hull of each view's points is its outline.
  for (auto& o : outlines) {
    std::vector<cv::Point2f> f(o.begin(), o.end()), hull;
    cv::convexHull(f, hull);
    o.assign(hull.begin(), hull.end());
  }
  return coveredField(size, outlines);
}

void expectCamera(const CameraCalibration& c, const scene::LensCamera& truth) {
  ASSERT_TRUE(c.status.ok()) << c.status.message;
  EXPECT_LT(c.rmsPx, 0.1);
  EXPECT_NEAR(c.camera.cameraMatrix(0, 0), truth.fx, 0.005 * truth.fx);
  EXPECT_NEAR(c.camera.cameraMatrix(1, 1), truth.fy, 0.005 * truth.fy);
  EXPECT_NEAR(c.camera.cameraMatrix(0, 2), truth.cx, 3.0);
  EXPECT_NEAR(c.camera.cameraMatrix(1, 2), truth.cy, 3.0);
  EXPECT_NEAR(c.camera.distortion.at<double>(0), truth.k1, 0.02);
  // Where it matters: the estimated camera puts the true camera's rays where it does.
  const cv::Mat all(truth.size, CV_8U, cv::Scalar(255));
  const double error = test::modelError(c.camera, {truth.matrix(), truth.distortion(), truth.size},
                                        covered(c, truth.size));
  std::printf("model error over the covered field %.4f px (whole field %.4f px)\n", error,
              test::modelError(c.camera, {truth.matrix(), truth.distortion(), truth.size}, all));
  EXPECT_LT(error, 0.05);
}

TEST(CameraCalibration, ChessboardViewsGiveTheRenderedCamera) {
  const auto camera = test::testCamera();
  const auto c = calibrateCamera(test::chessboard(), camera.size,
                                 renderViews(test::chessboard(), camera, 10, 21));
  expectCamera(c, camera);
  EXPECT_GT(c.coverage, 0.3);
}

TEST(CameraCalibration, CharucoViewsSomeShowingPartOfThePlateGiveTheRenderedCamera) {
  const auto camera = test::testCamera();
  const BoardSpec board = test::charucoBoard();
  std::vector<PlateView> views = renderViews(board, camera, 8, 23);
  // Two close views reaching into the image's corners, each with part of the plate outside.
  for (const auto& [target, name] : {std::pair{cv::Point2d(85, 60), "top-left"},
                                     std::pair{cv::Point2d(15, 10), "bottom-right"}}) {
    scene::PlaneScene s;
    s.camera = camera;
    s.placement = scene::lookAtPlane(target, 180, 25, 30, -6, camera);
    scene::addCharucoPlate(s, board.cols + 1, board.rows + 1, board.pitchMm, board.markerMm,
                           board.dictionary);
    s.noiseSigma = 2;
    views.push_back(detectPlate(s.render(), board, name));
  }
  const auto c = calibrateCamera(board, camera.size, views);
  expectCamera(c, camera);
  for (const std::string partial : {"top-left", "bottom-right"}) {
    const auto v = std::find_if(c.views.begin(), c.views.end(),
                                [&](const ViewFit& f) { return f.name == partial; });
    ASSERT_NE(v, c.views.end());
    EXPECT_TRUE(v->used) << v->status.message;
    EXPECT_LT(v->points.size(), 88u);
    EXPECT_EQ(v->points.size(), v->ids.size());
    EXPECT_LT(v->rmsPx, 0.1);
  }
}

TEST(CameraCalibration, ADistortedWideLensKeepsItsHigherTerms) {
  // k1 -0.22 and k2 0.08 over a 1280x1024 field at f = 1500: k2 is plainly visible.
  const auto c = calibrateCamera(test::chessboard(), test::testCamera().size,
                                 renderViews(test::chessboard(), test::testCamera(), 10, 21));
  ASSERT_TRUE(c.status.ok()) << c.status.message;
  EXPECT_NE(c.distortionModel.find("k2"), std::string::npos) << c.distortionModel;
}

TEST(CameraCalibration, ANarrowLensGetsNoTermsTheViewsCannotTellApart) {
  // f = 4000 px on 640x480 (a 9 degree field) with k1 alone: k2 and k3 would fit the noise.
  scene::LensCamera narrow;
  narrow.size = {640, 480};
  narrow.fx = narrow.fy = 4000, narrow.cx = 322, narrow.cy = 236;
  narrow.k1 = -0.05;
  const BoardSpec board{BoardSpec::Kind::Chessboard, 11, 8, 2.5, 0.0};
  const auto c = calibrateCamera(board, narrow.size, renderViews(board, narrow, 10, 5));
  ASSERT_TRUE(c.status.ok()) << c.status.message;
  EXPECT_EQ(c.distortionModel, "k1,p1,p2");
  EXPECT_EQ(c.camera.distortion.at<double>(1), 0.0);
  EXPECT_EQ(c.camera.distortion.at<double>(4), 0.0);
  // Every model was tried; the full one fits the points as well and the field worse.
  ASSERT_EQ(c.distortionCandidates.size(), 3u);
  const auto& full = c.distortionCandidates.back();
  EXPECT_EQ(full.terms, "k1,k2,p1,p2,k3");
  EXPECT_LT(c.rmsPx - full.rmsPx, 0.01);
  const cv::Mat all(narrow.size, CV_8U, cv::Scalar(255));
  const CameraModel truth{narrow.matrix(), narrow.distortion(), narrow.size};
  const double chosen = test::modelError(c.camera, truth, all);
  const double fullError = test::modelError(full.camera, truth, all);
  std::printf("narrow lens, model error over the whole field: chosen %.4f px, full model %.4f px\n",
              chosen, fullError);
  EXPECT_LE(chosen, fullError);
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
  EXPECT_FALSE(c.status.ok());
  EXPECT_NE(c.status.message.find("5 of 5"), std::string::npos) << c.status.message;
  EXPECT_NE(c.status.message.find("at least 8"), std::string::npos) << c.status.message;
}

TEST(CameraCalibration, RefusesAnRmsAboveTheLimit) {
  const auto camera = test::testCamera();
  CalibrationOptions strict;
  strict.maxRmsPx = 1e-6;
  const auto c = calibrateCamera(test::chessboard(), camera.size,
                                 renderViews(test::chessboard(), camera, 8, 24), strict);
  EXPECT_FALSE(c.status.ok());
  EXPECT_NE(c.status.message.find("RMS"), std::string::npos) << c.status.message;
}

}  // namespace
}  // namespace facet
