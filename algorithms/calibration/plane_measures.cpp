#include "algorithms/calibration/plane_measures.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

namespace facet {
namespace {

cv::Point2d inPlane(const WorldMapping* plane, cv::Point2d pixel) {
  return plane ? plane->toPlane(pixel) : pixel;
}

bool finite(cv::Point2d p) {
  return std::isfinite(p.x) && std::isfinite(p.y);
}

// The line fitted again in the plane to the measurement's inlier points, with the image fit's
// robust estimator at the plane's scale: its ends (the points' extent along it, in the order of
// `axis`), straightness and RMS. False when a point leaves the plane or the fit fails.
bool fitInPlane(const LineMeasurement& line, const WorldMapping& plane, cv::Point2d axis,
                LineInPlane& out) {
  std::vector<cv::Point2d> points;
  points.reserve(line.inliers.size());
  for (int i : line.inliers) {
    const cv::Point2d q = plane.toPlane(line.edgePoints[static_cast<std::size_t>(i)]);
    if (!finite(q)) return false;
    points.push_back(q);
  }
  const double scale = plane.mmPerPixelAt((line.p1 + line.p2) * 0.5);
  LineFitParams params;
  params.ransacThreshold *= scale;
  params.minScale *= scale;
  const auto fit = fitLineRobust(points, params);
  if (!fit) return false;
  const LineSegment seg = inlierSegment(*fit, points, axis);
  out.p1 = seg.p1;
  out.p2 = seg.p2;
  out.straightness = fit->straightness;
  out.rms = fit->rms;
  return true;
}

}  // namespace

double spanInPlane(const MeasuringPath& path, const WorldMapping* plane, double s0, double s1) {
  if (!plane) return s1 - s0;
  if (!path.isArc()) {
    const cv::Point2d centre = path.at(0, 0);
    cv::Point2d axis = plane->toPlane(centre + path.axisAt(0)) - plane->toPlane(centre);
    axis /= cv::norm(axis);
    return (plane->toPlane(path.at(s1, 0)) - plane->toPlane(path.at(s0, 0))).dot(axis);
  }
  const int steps = std::max(1, static_cast<int>(std::ceil(std::abs(s1 - s0))));
  double sum = 0.0;
  cv::Point2d from = plane->toPlane(path.at(s0, 0));
  for (int i = 1; i <= steps; ++i) {
    const cv::Point2d to = plane->toPlane(path.at(s0 + (s1 - s0) * i / steps, 0));
    sum += cv::norm(to - from);
    from = to;
  }
  return s1 >= s0 ? sum : -sum;
}

double midpointInPlane(const MeasuringPath& path, const WorldMapping* plane, double s0, double s1) {
  if (!plane || s0 == s1) return (s0 + s1) / 2;
  const double half = spanInPlane(path, plane, s0, s1) / 2;
  if (!std::isfinite(half)) return std::numeric_limits<double>::quiet_NaN();
  // The span from s0 grows steadily from 0 to 2 half between s0 and s1: false position with the
  // Illinois step keeps the bracket and converges in a few spans (an arc's costs a pixel's worth
  // of mappings per pixel of its length).
  double a = s0, b = s1, fa = -half, fb = half;
  double s = (s0 + s1) / 2;
  int side = 0;
  for (int it = 0; it < 60 && std::abs(b - a) > 1e-9; ++it) {
    s = (a * fb - b * fa) / (fb - fa);
    const double f = spanInPlane(path, plane, s0, s) - half;
    if (!std::isfinite(f)) return std::numeric_limits<double>::quiet_NaN();
    if (std::abs(f) < 1e-12) break;
    if ((f < 0) == (fa < 0)) {
      a = s, fa = f;
      if (side == -1) fb /= 2;
      side = -1;
    } else {
      b = s, fb = f;
      if (side == 1) fa /= 2;
      side = 1;
    }
  }
  return s;
}

std::optional<LineInPlane> lineInPlane(const MeasuringRect& rect, const LineMeasurement& line,
                                       const WorldMapping* plane) {
  const MeasuringPath path(rect);
  const cv::Point2d centre = inPlane(plane, {rect.cx, rect.cy});
  const cv::Point2d axis = inPlane(plane, cv::Point2d(rect.cx, rect.cy) + path.axisAt(0)) - centre;
  const cv::Point2d acrossSeen =
      inPlane(plane, cv::Point2d(rect.cx, rect.cy) + path.acrossAt(0)) - centre;
  if (!finite(centre) || !finite(axis) || !finite(acrossSeen)) return std::nullopt;
  LineInPlane out;
  if (plane && !line.inliers.empty()) {
    if (!fitInPlane(line, *plane, axis, out)) return std::nullopt;
  } else {
    out.p1 = inPlane(plane, line.p1);
    out.p2 = inPlane(plane, line.p2);
    if (!finite(out.p1) || !finite(out.p2)) return std::nullopt;
    const double scale = plane ? plane->mmPerPixelAt((line.p1 + line.p2) * 0.5) : 1.0;
    out.straightness = line.straightness * scale;
    out.rms = line.rms * scale;
  }
  const cv::Point2d along = out.p2 - out.p1;
  // Positive turns towards the plane's y, which is clockwise on screen.
  const double turn = std::atan2(axis.x * along.y - axis.y * along.x, axis.dot(along));
  out.angleFromAxis = -turn * 180.0 / CV_PI;
  // Across the axis in the plane: square to it there (the image's square to the axis is not,
  // on a tilted view), on the side of the rectangle's across direction.
  cv::Point2d across(-axis.y, axis.x);
  across /= cv::norm(across);
  if (across.dot(acrossSeen) < 0) across = -across;
  // The line p(k) = mid + k u meets the centre line c + m across where their difference vanishes.
  const cv::Point2d u = along / cv::norm(along);
  const cv::Point2d mid = (out.p1 + out.p2) * 0.5;
  const cv::Point2d v = centre - mid;
  const double cross = u.x * across.y - u.y * across.x;
  out.offset = std::abs(cross) > 1e-9 ? (v.x * u.y - v.y * u.x) / cross : 0.0;
  return out;
}

}  // namespace facet
