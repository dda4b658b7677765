#pragma once
// ChArUco corners located to the precision of facet's subpixel edges.
//
// OpenCV's aruco module finds the markers and, from the markers beside each corner, the corner
// to about a tenth of a pixel together with its identity (OpenCV's charuco corner id, which is
// the plate point's index: row by row from the corner next to the board's dark first square).
// Each corner is then re-located as the intersection of its two edge lines (edge_curve.hpp), as
// a chessboard's is. The edge points come from grey profiles across each line rather than from
// the image's edge map: every edge between a dark and a light square has, inside the light
// square, the black border of a marker running parallel to it (SQUARE - MARKER) / 2 away, a few
// pixels, well inside the reach of an edge fit that models one step. The profile estimator
// (profile_edges.hpp) fits that border as a neighbouring step and takes it out, so the edge
// stays unbiased by construction.
//
// A corner whose edge lines cannot be fitted (at the image's border, hidden) is dropped and the
// rest kept: a ChArUco view is usable in part. Squares too small for edge lines at the image's
// blur keep OpenCV's saddle-point position, and the detection's note says how many.

#include <opencv2/core.hpp>

#include "algorithms/calibration/board_spec.hpp"
#include "algorithms/calibration/pattern_detection.hpp"

namespace facet {

// `image`: 8-bit or 16-bit grey; `board` a charuco board. The detection's `ids` name the corners
// found, in increasing order.
PatternDetection detectCharuco(const cv::Mat& image, const BoardSpec& board);

}  // namespace facet
