#pragma once
// Chessboard inner corners located to the precision of facet's subpixel edges.
//
// OpenCV's findChessboardCornersSB finds and orders the grid (to about 0.1 px); each corner is
// then re-located as the intersection of the two edge lines that cross there: the Facet-model
// subpixel edge points of both lines, away from the junction itself (where the blurred X-shape
// bends every edge), are fitted with a quadratic each (a lens-distorted straight line is curved)
// and the two curves intersected. Straight edges are located without bias under any symmetric
// blur, so the corner inherits that, while a saddle or corner-response fit on the grey values
// shifts with the blur and the perspective angle of the X.
//
// The order is the plate's (board_spec.hpp): the origin next to the dark outer corner square,
// x along the columns, y along the rows, z into the plate.

#include <opencv2/core.hpp>

#include "algorithms/calibration/board_spec.hpp"
#include "algorithms/calibration/calibration_failure.hpp"
#include "algorithms/calibration/pattern_detection.hpp"
#include "algorithms/status/status.hpp"

namespace facet {

// `image`: 8-bit or 16-bit grey.
PatternDetection detectChessboard(const cv::Mat& image, const BoardSpec& board);

// Refines coarse corners (plate order, cols x rows) in place; fails with PatternNotFound when a
// corner has too few clean edge points on either line (partly hidden). A corner whose squares
// are too small for clean edge points at the image's blur (under about 25 px at blur 0.6 seen
// square on) is refined by OpenCV's saddle point instead; `saddleCorners` counts them.
Status<CalibrationFailure> refineChessboardCorners(const cv::Mat& image, int cols, int rows,
                                                   std::vector<cv::Point2d>& corners,
                                                   int* saddleCorners = nullptr);

}  // namespace facet
