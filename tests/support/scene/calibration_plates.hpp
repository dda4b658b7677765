#pragma once
// Calibration plates and a plate with holes as plane scenes (plane_scene.hpp), in the plate frame
// of the design: x along the columns, y along the rows, z into the plate, mm.

#include <cstdint>
#include <vector>

#include <opencv2/core.hpp>

#include "tests/support/scene/plane_scene.hpp"

namespace facet::scene {

// A light plate (margin of one square beyond the squares) with (cols+1) x (rows+1) squares; the
// square at the origin's outer diagonal, (-pitch..0, -pitch..0), is dark. Inner corner (c, r)
// lies at (c * pitch, r * pitch).
void addChessboardPlate(PlaneScene& scene, int cols, int rows, double pitchMm, double dark = 25,
                        double light = 225);
// A ChArUco plate laid out as OpenCV 4.6's
// cv::aruco::CharucoBoard::create(squaresX, squaresY, squareMm, markerMm,
// getPredefinedDictionary(dictionary)), with a light margin of one square. OpenCV's board frame
// has its origin at the board's outer top-left corner, x along the columns and y DOWN the
// printed board (its objPoints put marker 0 in the top row and its chessboard corners at
// (c+1, r+1) * square, as CharucoBoard::draw shows); the plate frame here is that frame less
// (square, square), so its origin is the first inner corner and inner corner (c, r) lies at
// (c * square, r * square), OpenCV's ChArUco corner id r * (squaresX - 1) + c. The top-left
// square is dark; markers 0, 1, 2... sit centred in the light squares, row by row, with a black
// border one bit wide. charuco_plate_test.cpp checks all of this against OpenCV.
void addCharucoPlate(PlaneScene& scene, int squaresX, int squaresY, double squareMm,
                     double markerMm, int dictionary, double dark = 25, double light = 225);
// A light plate with cols x rows dark discs at (c * pitch, r * pitch), margin of one pitch.
void addCirclePlate(PlaneScene& scene, int cols, int rows, double pitchMm, double diameterMm,
                    double dark = 25, double light = 225);
// The true image positions of the pattern points (row by row, x fastest).
std::vector<cv::Point2d> patternImagePoints(const PlaneScene& scene, int cols, int rows,
                                            double pitchMm);

}  // namespace facet::scene

namespace facet::scene {

// A placement for view `index` of a calibration series: the plate tilted by up to `maxTiltDeg`
// about a random in-plane axis, spun by up to 25 degrees, its pattern (extent `patternMm`, plus
// `marginMm`) filling `fill` (0..1, drawn from [0.45, 0.75] by default) of the image width and
// shifted around the field so that a series covers it. Deterministic in (seed, index); the
// whole pattern plus margin stays inside the image.
PlanePlacement seriesPlacement(const LensCamera& camera, cv::Size2d patternMm, double marginMm,
                               std::uint64_t seed, int index, double maxTiltDeg = 40);

}  // namespace facet::scene
