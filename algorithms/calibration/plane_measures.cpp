#include "algorithms/calibration/plane_measures.hpp"

#include <algorithm>
#include <cmath>

namespace facet {
namespace {

cv::Point2d inPlane(const WorldMapping* plane, cv::Point2d pixel) {
  return plane ? plane->toPlane(pixel) : pixel;
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

LineInPlane lineInPlane(const MeasuringRect& rect, const LineMeasurement& line,
                        const WorldMapping* plane) {
  const MeasuringPath path(rect);
  const cv::Point2d centre(rect.cx, rect.cy);
  LineInPlane out;
  out.p1 = inPlane(plane, line.p1);
  out.p2 = inPlane(plane, line.p2);
  const cv::Point2d axis = inPlane(plane, centre + path.axisAt(0)) - inPlane(plane, centre);
  const cv::Point2d along = out.p2 - out.p1;
  // Positive turns towards the plane's y, which is clockwise on screen.
  const double turn = std::atan2(axis.x * along.y - axis.y * along.x, axis.dot(along));
  out.angleFromAxis = -turn * 180.0 / CV_PI;
  // Across the axis in the plane: square to it there (the image's square to the axis is not,
  // on a tilted view), on the side of the rectangle's across direction.
  cv::Point2d across(-axis.y, axis.x);
  across /= cv::norm(across);
  if (across.dot(inPlane(plane, centre + path.acrossAt(0)) - inPlane(plane, centre)) < 0)
    across = -across;
  // The line p(k) = mid + k u meets the centre line c + m across where their difference vanishes.
  const cv::Point2d u = along / cv::norm(along);
  const cv::Point2d mid = (out.p1 + out.p2) * 0.5;
  const cv::Point2d v = inPlane(plane, centre) - mid;
  const double cross = u.x * across.y - u.y * across.x;
  out.offset = std::abs(cross) > 1e-9 ? (v.x * u.y - v.y * u.x) / cross : 0.0;
  const double scale = plane ? plane->mmPerPixelAt((line.p1 + line.p2) * 0.5) : 1.0;
  out.straightness = line.straightness * scale;
  out.rms = line.rms * scale;
  return out;
}

}  // namespace facet
