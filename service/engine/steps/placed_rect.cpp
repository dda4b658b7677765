#include "service/engine/steps/placed_rect.hpp"

#include <algorithm>
#include <cmath>

#include "algorithms/geometry/pose2d.hpp"
#include "algorithms/geometry/projective_map.hpp"

namespace facet::service {

MeasuringRect placeRect(const cv::Matx33d& frame, cv::Point2d centre, double length, double width,
                        double angleDeg) {
  const double a = radians(angleDeg);
  const cv::Point2d axis(std::cos(a), -std::sin(a));
  const cv::Point2d c = mapPoint(frame, centre);
  // A unit step along the axis shows the frame's rotation and scale at the centre.
  const cv::Point2d d = mapPoint(frame, centre + axis) - c;
  const double scale = cv::norm(d);
  return {.cx = c.x,
          .cy = c.y,
          .length = length * scale,
          .width = width * scale,
          .angle = degrees(std::atan2(-d.y, d.x))};
}

MeasuringArc placeArc(const cv::Matx33d& frame, cv::Point2d centre, double radius,
                      double startAngleDeg, double extentDeg, double width) {
  const cv::Point2d c = mapPoint(frame, centre);
  const cv::Point2d d = mapPoint(frame, centre + cv::Point2d(1, 0)) - c;
  const double scale = cv::norm(d);
  return {.cx = c.x,
          .cy = c.y,
          .radius = radius * scale,
          .startAngle = startAngleDeg + degrees(std::atan2(-d.y, d.x)),
          .extent = extentDeg,
          .width = width * scale};
}

std::vector<cv::Point2d> arcOutline(const MeasuringArc& arc) {
  const MeasuringPath path(arc);
  // About one point per 3 degrees: smooth on screen at any radius a part shows.
  const int steps = std::max(2, static_cast<int>(std::ceil(std::abs(arc.extent) / 3.0)));
  std::vector<cv::Point2d> outline;
  for (const double t : {arc.width / 2, -arc.width / 2})
    for (int i = 0; i <= steps; ++i) {
      const double f = static_cast<double>(t > 0 ? i : steps - i) / steps;
      outline.push_back(path.at((f - 0.5) * path.length(), t));
    }
  return outline;
}

std::vector<cv::Point2d> rectCorners(const MeasuringRect& rect) {
  const MeasuringPath path(rect);
  const double s = rect.length / 2, t = rect.width / 2;
  return {path.at(-s, -t), path.at(s, -t), path.at(s, t), path.at(-s, t)};
}

bool insideRect(const MeasuringRect& rect, cv::Point2d p) {
  const MeasuringPath path(rect);
  const cv::Point2d v = p - cv::Point2d(rect.cx, rect.cy);
  return std::abs(v.dot(path.axisAt(0))) <= rect.length / 2 &&
         std::abs(v.dot(path.acrossAt(0))) <= rect.width / 2;
}

}  // namespace facet::service
