#pragma once
// Rendered plate views shared by the calibration tests.
#include <cstdint>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "algorithms/calibration/board_spec.hpp"
#include "algorithms/calibration/world_mapping.hpp"
#include "tests/support/scene/calibration_plates.hpp"

namespace facet::test {

inline scene::LensCamera testCamera() {
  scene::LensCamera c;
  c.fx = 1500, c.fy = 1502, c.cx = 645.2, c.cy = 508.7;
  c.k1 = -0.22, c.k2 = 0.08, c.p1 = 0.0012, c.p2 = -0.0008;
  return c;
}

// The test camera looking at a plane tilted 35 degrees from 280 mm, with the exact mapping of
// the plane into the image (the renderer's) and back (the code under test's).
struct TiltedPlane {
  scene::LensCamera camera = testCamera();
  scene::PlanePlacement placement = scene::lookAtPlane({40, 30}, 280, 35, 20, 10, camera);
  WorldMapping mapping{CameraModel{camera.matrix(), camera.distortion(), camera.size},
                       PlanePose{placement.rotation, placement.translationMm, 0.0}};
  [[nodiscard]] cv::Point2d pixelOf(cv::Point2d mm) const {
    return camera.project(placement.toCamera(mm));
  }
};

inline scene::PlaneScene plateScene(const BoardSpec& board, const scene::LensCamera& camera,
                                    std::uint64_t seed, int index, double noise = 2.0) {
  scene::PlaneScene s;
  s.camera = camera;
  const double margin = board.kind == BoardSpec::Kind::Circles ? board.pitchMm : 2 * board.pitchMm;
  s.placement = scene::seriesPlacement(
      camera, {(board.cols - 1) * board.pitchMm, (board.rows - 1) * board.pitchMm}, margin, seed,
      index);
  if (board.kind == BoardSpec::Kind::Chessboard)
    scene::addChessboardPlate(s, board.cols, board.rows, board.pitchMm);
  else if (board.kind == BoardSpec::Kind::Charuco)
    scene::addCharucoPlate(s, board.cols + 1, board.rows + 1, board.pitchMm, board.markerMm,
                           board.dictionary);
  else
    scene::addCirclePlate(s, board.cols, board.rows, board.pitchMm, board.diameterMm);
  s.noiseSigma = noise;
  s.seed = seed * 7717 + static_cast<std::uint64_t>(index);
  return s;
}

inline BoardSpec chessboard() {
  return {BoardSpec::Kind::Chessboard, 11, 8, 10.0, 0.0};
}
inline BoardSpec circleGrid() {
  return {BoardSpec::Kind::Circles, 9, 7, 12.0, 6.0};
}
// 12 x 9 squares: the chessboard's 11 x 8 inner corners, with 54 markers.
inline BoardSpec charucoBoard() {
  std::string why;
  return *parseBoardSpec("charuco:12x9:10:7:DICT_5X5_100", why);
}

}  // namespace facet::test
