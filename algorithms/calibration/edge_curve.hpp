#pragma once
// A plate's edge line near a corner, as a gently curved line: a lens-distorted straight edge
// bends, and over one or two squares a quadratic across the line follows that bend. A corner is
// where the two edge lines through it cross; both chessboard and ChArUco corners are located
// this way from subpixel edge points away from the junction.

#include <optional>
#include <vector>

#include <opencv2/core.hpp>

namespace facet {

struct EdgeCurve {
  cv::Point2d origin, along, across;  // local frame: along the line, across it (unit vectors)
  double a = 0, b = 0, q = 0;         // across = a + b t + q t^2, t along
  [[nodiscard]] cv::Point2d point(double t) const {
    return origin + t * along + (a + b * t + q * t * t) * across;
  }
  [[nodiscard]] cv::Point2d tangent(double t) const { return along + (b + 2 * q * t) * across; }
};

// Least-squares quadratic through the edge points of one line (origin, along and across set by
// the caller at the corner); one pass drops points more than 3 RMS (at least 0.2 px) off. False
// when either side of the origin has fewer than 4 points.
bool fitEdgeCurve(const std::vector<cv::Point2d>& points, EdgeCurve& curve);

// Where the two curves cross, by Newton steps from `start`; nothing when they run parallel.
std::optional<cv::Point2d> intersectEdgeCurves(const EdgeCurve& u, const EdgeCurve& v,
                                               cv::Point2d start);

}  // namespace facet
