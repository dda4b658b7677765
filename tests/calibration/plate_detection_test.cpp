// Pattern points found in rendered plate views, against the renderer's exact projections.
#include <algorithm>
#include <cmath>

#include <gtest/gtest.h>
#include <opencv2/aruco/charuco.hpp>
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

// The truth of the corners a detection names by id.
double rmsErrorById(const PatternDetection& d, const std::vector<cv::Point2d>& truth) {
  double s = 0;
  for (std::size_t i = 0; i < d.points.size(); ++i)
    s += std::pow(cv::norm(d.points[i] - truth[static_cast<std::size_t>(d.ids[i])]), 2);
  return std::sqrt(s / static_cast<double>(d.points.size()));
}

// OpenCV's own ChArUco corners (4.6 returns them +0.5 px off in x and y, a bug fixed upstream;
// undone here so that the comparison is with what the pipeline means to give).
double openCvCharucoRms(const cv::Mat& image, const BoardSpec& board,
                        const std::vector<cv::Point2d>& truth) {
  const auto dictionary = cv::aruco::getPredefinedDictionary(board.dictionary);
  const auto cvBoard = cv::aruco::CharucoBoard::create(
      board.cols + 1, board.rows + 1, static_cast<float>(board.pitchMm),
      static_cast<float>(board.markerMm), dictionary);
  std::vector<std::vector<cv::Point2f>> markers;
  std::vector<int> markerIds, ids;
  std::vector<cv::Point2f> corners;
  cv::aruco::detectMarkers(image, dictionary, markers, markerIds);
  cv::aruco::interpolateCornersCharuco(markers, markerIds, image, cvBoard, corners, ids);
  double s = 0;
  for (std::size_t i = 0; i < corners.size(); ++i)
    s += std::pow(cv::norm(cv::Point2d(corners[i]) - cv::Point2d(0.5, 0.5) -
                           truth[static_cast<std::size_t>(ids[i])]),
                  2);
  return corners.empty() ? 1e9 : std::sqrt(s / static_cast<double>(corners.size()));
}

TEST(PlateDetection, CharucoCornersNamedByIdAndSubpixel) {
  const BoardSpec board = test::charucoBoard();
  for (int i = 0; i < 3; ++i) {
    auto s = test::plateScene(board, test::testCamera(), 11, i);
    s.lensBlurSigma = 0.7;
    const auto truth = scene::patternImagePoints(s, board.cols, board.rows, board.pitchMm);
    const cv::Mat image = s.render();
    const PlateView view = detectPlate(image, board, "view");
    ASSERT_TRUE(view.detection.status.ok()) << view.detection.status.message;
    ASSERT_EQ(view.detection.points.size(), truth.size()) << view.detection.note;
    ASSERT_EQ(view.detection.ids.size(), truth.size());
    for (std::size_t k = 0; k < truth.size(); ++k) EXPECT_EQ(view.detection.ids[k], int(k));
    EXPECT_TRUE(view.detection.note.empty()) << view.detection.note;
    const double rms = rmsErrorById(view.detection, truth);
    const double opencv = openCvCharucoRms(image, board, truth);
    std::printf("view %d: corner RMS %.4f px (OpenCV's, corrected by 0.5 px: %.4f px)\n", i, rms,
                opencv);
    // The marker border beside every edge does not pull the edge lines.
    EXPECT_LT(rms, 0.02);
    EXPECT_LT(rms, 0.5 * opencv);
  }
}

TEST(PlateDetection, APartialCharucoViewKeepsTheCornersInView) {
  const BoardSpec board = test::charucoBoard();
  const auto camera = test::testCamera();
  scene::PlaneScene s;
  s.camera = camera;
  // 100 px squares, the board's top-left part beyond the image's left and top borders.
  s.placement = scene::lookAtPlane({80, 55}, 150, 20, 60, 8, camera);
  scene::addCharucoPlate(s, board.cols + 1, board.rows + 1, board.pitchMm, board.markerMm,
                         board.dictionary);
  s.noiseSigma = 2;
  s.lensBlurSigma = 0.7;
  const auto truth = scene::patternImagePoints(s, board.cols, board.rows, board.pitchMm);
  std::size_t inside = 0;
  for (const auto& p : truth)
    inside += p.x > 0 && p.y > 0 && p.x < camera.size.width - 1 && p.y < camera.size.height - 1;
  ASSERT_LT(inside, truth.size());  // the scene is what the test means
  const PlateView view = detectPlate(s.render(), board, "partial");
  ASSERT_TRUE(view.detection.status.ok()) << view.detection.status.message;
  const std::size_t found = view.detection.points.size();
  const double rms = rmsErrorById(view.detection, truth);
  std::printf("%zu of %zu corners in the image, %zu found, RMS %.4f px: %s\n", inside, truth.size(),
              found, rms, view.detection.note.c_str());
  // OpenCV names a corner only from two whole markers beside it; the corners next to the
  // markers the border cuts are found from their neighbours. Those closer to the border than
  // the lines' clean stretches are not.
  EXPECT_GE(found, inside * 8 / 10);
  EXPECT_LT(found, truth.size());
  EXPECT_NE(view.detection.note.find(" of 88 corners"), std::string::npos) << view.detection.note;
  EXPECT_TRUE(std::is_sorted(view.detection.ids.begin(), view.detection.ids.end()));
  EXPECT_LT(rms, 0.03);
}

TEST(PlateDetection, ACharucoPlateIsFoundAlikeIn16BitImagesAndNotInDegenerateOnes) {
  const BoardSpec board = test::charucoBoard();
  const auto s = test::plateScene(board, test::testCamera(), 11, 1);
  const auto truth = scene::patternImagePoints(s, board.cols, board.rows, board.pitchMm);
  cv::Mat image16;
  s.render().convertTo(image16, CV_16U, 256.0);
  const PlateView view = detectPlate(image16, board, "16 bit");
  ASSERT_TRUE(view.detection.status.ok()) << view.detection.status.message;
  EXPECT_EQ(view.detection.points.size(), truth.size());
  EXPECT_LT(rmsErrorById(view.detection, truth), 0.02);
  for (const cv::Mat& degenerate : {cv::Mat(480, 640, CV_8U, cv::Scalar(128)),
                                    cv::Mat(6, 6, CV_8U, cv::Scalar(0)), cv::Mat()}) {
    const PlateView none = detectPlate(degenerate, board, "degenerate");
    EXPECT_FALSE(none.detection.status.ok());
    EXPECT_FALSE(none.detection.status.message.empty());
    EXPECT_TRUE(none.detection.points.empty());
  }
}

TEST(PlateDetection, ACharucoSpecThatDoesNotMatchThePlateIsRefusedWithAReason) {
  const auto s = test::plateScene(test::charucoBoard(), test::testCamera(), 11, 0);
  const cv::Mat image = s.render();
  std::string why;
  // 8 x 6 squares hold markers 0-23; the 12 x 9 plate shows 0-53.
  const auto fewer = parseBoardSpec("charuco:8x6:10:7:DICT_5X5_100", why);
  const PlateView small = detectPlate(image, *fewer, "view");
  EXPECT_FALSE(small.detection.status.ok());
  EXPECT_NE(small.detection.status.message.find("is the board spec right?"), std::string::npos)
      << small.detection.status.message;
  const auto otherDictionary = parseBoardSpec("charuco:12x9:10:7:DICT_4X4_100", why);
  const PlateView other = detectPlate(image, *otherDictionary, "view");
  EXPECT_FALSE(other.detection.status.ok());
  EXPECT_NE(other.detection.status.message.find("DICT_4X4_100"), std::string::npos)
      << other.detection.status.message;
}

}  // namespace
}  // namespace facet
