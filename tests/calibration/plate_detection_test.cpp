// Pattern points found in rendered plate views, against the renderer's exact projections.
#include <cmath>

#include <gtest/gtest.h>
#include <opencv2/calib3d.hpp>

#include "algorithms/calibration/camera_calibration.hpp"
#include "algorithms/calibration/circle_marks.hpp"
#include "tests/calibration/calibration_scenes.hpp"

namespace facet {
namespace {

double rmsError(const std::vector<cv::Point2d>& a, const std::vector<cv::Point2d>& b) {
  double s = 0;
  for (std::size_t i = 0; i < a.size(); ++i) s += std::pow(cv::norm(a[i] - b[i]), 2);
  return std::sqrt(s / static_cast<double>(a.size()));
}

TEST(PlateDetection, ChessboardCornersInPlateOrderAndSubpixel) {
  const BoardSpec board = test::chessboard();
  for (int i = 0; i < 3; ++i) {
    const auto s = test::plateScene(board, test::testCamera(), 11, i);
    const auto truth = scene::patternImagePoints(s, board.cols, board.rows, board.pitchMm);
    const PlateView view = detectPlate(s.render(), board, "view");
    ASSERT_TRUE(view.detection.status.ok()) << view.detection.status.message;
    ASSERT_EQ(view.detection.points.size(), truth.size());
    // Plate order: the first point is the origin, not a corner of the other end.
    EXPECT_LT(cv::norm(view.detection.points[0] - truth[0]), 0.5);
    const double rms = rmsError(view.detection.points, truth);
    std::printf("view %d: corner RMS %.4f px\n", i, rms);
    EXPECT_LT(rms, 0.05);
  }
}

TEST(PlateDetection, SquaresTooSmallForEdgeLinesAreLocatedBySaddlePointAndSaySo) {
  // The example station's camera (f = 2400 px) with 2 mm squares 260 mm away: 18 px squares,
  // too small for clean edge points between the junctions at blur 0.6.
  scene::LensCamera camera;
  camera.size = {640, 480};
  camera.fx = camera.fy = 2400, camera.cx = 319.5, camera.cy = 239.5;
  camera.k1 = -0.012;
  scene::PlaneScene s;
  s.camera = camera;
  s.placement = scene::lookAtPlane({10, 7}, 260, 15, 30, 5, camera);
  scene::addChessboardPlate(s, 11, 8, 2.0);
  s.lensBlurSigma = 0.6;
  s.noiseSigma = 1.5;
  const BoardSpec board{BoardSpec::Kind::Chessboard, 11, 8, 2.0, 0.0};
  const auto truth = scene::patternImagePoints(s, board.cols, board.rows, board.pitchMm);
  const PlateView view = detectPlate(s.render(), board, "small");
  ASSERT_TRUE(view.detection.status.ok()) << view.detection.status.message;
  EXPECT_NE(view.detection.note.find("88 of 88 corners by saddle point"), std::string::npos)
      << view.detection.note;
  const double rms = rmsError(view.detection.points, truth);
  std::printf("18 px squares: corner RMS %.4f px\n", rms);
  EXPECT_LT(rms, 0.1);
  // Squares large enough (the shared scenes): no note.
  const PlateView large =
      detectPlate(test::plateScene(test::chessboard(), test::testCamera(), 11, 0).render(),
                  test::chessboard(), "large");
  EXPECT_TRUE(large.detection.note.empty()) << large.detection.note;
}

TEST(PlateDetection, CircleCentresArePerspectiveCorrectWithTheTrueCamera) {
  const BoardSpec board = test::circleGrid();
  const auto camera = test::testCamera();
  for (int i = 0; i < 3; ++i) {
    const auto s = test::plateScene(board, camera, 12, i);
    const auto truth = scene::patternImagePoints(s, board.cols, board.rows, board.pitchMm);
    const cv::Mat image = s.render();
    const CircleMarks marks = detectCircleMarks(image, board);
    ASSERT_TRUE(marks.detection.status.ok()) << marks.detection.status.message;
    EXPECT_LT(cv::norm(marks.detection.points[0] - truth[0]), 1.0);
    const double ellipseRms = rmsError(marks.detection.points, truth);
    CameraModel model{camera.matrix(), camera.distortion(), camera.size};
    const auto centres = perspectiveCentres(marks, model, s.placement.rotation);
    const double rms = rmsError(centres, truth);
    std::printf("view %d: ellipse centres %.4f px, perspective centres %.4f px\n", i, ellipseRms,
                rms);
    EXPECT_LT(rms, 0.03);
    EXPECT_LT(rms, ellipseRms);
  }
}

TEST(PlateDetection, WrongBoardSpecIsNotFoundWithAReason) {
  const auto s = test::plateScene(test::chessboard(), test::testCamera(), 11, 0);
  BoardSpec wrong = test::chessboard();
  wrong.cols = 9, wrong.rows = 6;
  const PlateView view = detectPlate(s.render(), wrong, "view");
  // OpenCV may find a 9x6 part of the 11x8 board; the squares beyond its border give it away.
  EXPECT_FALSE(view.detection.status.ok());
  EXPECT_NE(view.detection.status.message.find("9x6"), std::string::npos)
      << view.detection.status.message;
}

TEST(PlateDetection, HeavilyBlurredBoardIsSkippedWithAReason) {
  auto s = test::plateScene(test::chessboard(), test::testCamera(), 11, 0);
  s.lensBlurSigma = 12;
  s.fineFactor = 1;  // blur on the pixel grid: this test is about the refusal, not the model
  const PlateView view = detectPlate(s.render(), test::chessboard(), "view");
  EXPECT_FALSE(view.detection.status.ok());
  EXPECT_FALSE(view.detection.status.message.empty());
}

}  // namespace
}  // namespace facet
