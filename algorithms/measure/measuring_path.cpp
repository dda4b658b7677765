#include "algorithms/measure/measuring_path.hpp"

#include <algorithm>
#include <cmath>

namespace facet {

MeasuringPath::MeasuringPath(const MeasuringRect& rect)
    : centre_(rect.cx, rect.cy),
      length_(rect.length),
      width_(rect.width),
      angle_(rect.angle * CV_PI / 180.0),
      cos_(std::cos(angle_)),
      sin_(std::sin(angle_)) {}

MeasuringPath::MeasuringPath(const MeasuringArc& arc)
    : arc_(true),
      centre_(arc.cx, arc.cy),
      length_(std::abs(arc.extent) * CV_PI / 180.0 * arc.radius),
      width_(arc.width),
      angle_((arc.startAngle + arc.extent / 2.0) * CV_PI / 180.0),
      radius_(arc.radius),
      sign_(arc.extent < 0 ? -1.0 : 1.0) {}

cv::Point2d MeasuringPath::arcAt(double s, double t) const {
  const double phi = angle_ + sign_ * s / radius_;
  const double r = radius_ + t;
  return {centre_.x + r * std::cos(phi), centre_.y - r * std::sin(phi)};
}

cv::Point2d MeasuringPath::axisAt(double s) const {
  if (!arc_) return {cos_, -sin_};
  const double phi = angle_ + sign_ * s / radius_;
  return {-sign_ * std::sin(phi), -sign_ * std::cos(phi)};
}

cv::Point2d MeasuringPath::arcAcrossAt(double s) const {
  const double phi = angle_ + sign_ * s / radius_;
  return {std::cos(phi), -std::sin(phi)};
}

cv::Rect2d MeasuringPath::bounds() const {
  double x0 = 1e300, y0 = 1e300, x1 = -1e300, y1 = -1e300;
  // Corners for a rectangle; for an arc a dense walk along both rims.
  const int steps = arc_ ? std::max(2, static_cast<int>(length_)) : 1;
  for (int i = 0; i <= steps; ++i) {
    const double s = -length_ / 2 + length_ * i / steps;
    for (double t : {-width_ / 2, width_ / 2}) {
      const cv::Point2d p = at(s, t);
      x0 = std::min(x0, p.x), y0 = std::min(y0, p.y);
      x1 = std::max(x1, p.x), y1 = std::max(y1, p.y);
    }
  }
  return {x0, y0, x1 - x0, y1 - y0};
}

}  // namespace facet
