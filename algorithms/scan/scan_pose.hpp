#pragma once
// The rigid pose that maps a scan into its reference's frame:
//     p_ref = R(theta) * p + (x, y),   R(theta) = [[cos, -sin], [sin, cos]]
// R is the usual counter-clockwise rotation of a right-handed metric frame (x forward, y left).
// This differs on purpose from facet::Pose2D, which lives in image coordinates (y down).
// theta is held in radians and printed in degrees.

#include <cmath>
#include <numbers>

#include <Eigen/Core>

namespace facet::scan {

struct ScanPose {
  double x = 0.0;      // metres
  double y = 0.0;      // metres
  double theta = 0.0;  // radians, counter-clockwise

  [[nodiscard]] Eigen::Vector2d apply(const Eigen::Vector2d& p) const {
    const double c = std::cos(theta), s = std::sin(theta);
    return {c * p.x() - s * p.y() + x, s * p.x() + c * p.y() + y};
  }

  [[nodiscard]] Eigen::Vector2d rotate(const Eigen::Vector2d& v) const {
    const double c = std::cos(theta), s = std::sin(theta);
    return {c * v.x() - s * v.y(), s * v.x() + c * v.y()};
  }

  // (this * other).apply(p) == this->apply(other.apply(p))
  [[nodiscard]] ScanPose operator*(const ScanPose& other) const {
    const Eigen::Vector2d t = apply({other.x, other.y});
    return {t.x(), t.y(), std::remainder(theta + other.theta, 2.0 * std::numbers::pi)};
  }

  [[nodiscard]] ScanPose inverse() const {
    const double c = std::cos(theta), s = std::sin(theta);
    return {-(c * x + s * y), s * x - c * y, -theta};
  }
};

}  // namespace facet::scan
