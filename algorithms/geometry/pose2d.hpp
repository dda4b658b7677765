#pragma once
// A 2D similarity pose in image coordinates (x right, y down, pixel centres at integers).
//
// It maps a model point p, given relative to the model's reference point, to the image point
//     q = t + s * R(a) * p,   R(a) = [[cos a, sin a], [-sin a, cos a]]
// so that a positive angle turns counter-clockwise as seen on screen (y points down).
// Angles are held in radians and printed in degrees.

#include <cmath>
#include <numbers>

#include <opencv2/core/types.hpp>

namespace facet {

inline double degrees(double radians) {
  return radians * 180.0 / std::numbers::pi;
}
inline double radians(double degrees) {
  return degrees * std::numbers::pi / 180.0;
}

// Wraps an angle to (-pi, pi].
inline double wrapAngle(double a) {
  a = std::remainder(a, 2.0 * std::numbers::pi);
  return a <= -std::numbers::pi ? a + 2.0 * std::numbers::pi : a;
}

struct Pose2D {
  double x = 0.0;  // translation t, pixels
  double y = 0.0;
  double angle = 0.0;  // a, radians, counter-clockwise on screen
  double scale = 1.0;  // s, unitless

  // apply() with s * cos a and s * sin a taken once, for mapping many points.
  struct Map {
    double x, y, c, s;
    [[nodiscard]] cv::Point2d operator()(cv::Point2d p) const {
      return {x + c * p.x + s * p.y, y - s * p.x + c * p.y};
    }
  };
  [[nodiscard]] Map map() const { return {x, y, std::cos(angle) * scale, std::sin(angle) * scale}; }

  // q = t + s * R(a) * p
  [[nodiscard]] cv::Point2d apply(cv::Point2d p) const { return map()(p); }

  // Rotates and scales a direction vector (no translation).
  [[nodiscard]] cv::Point2d applyToVector(cv::Point2d v) const {
    const double c = std::cos(angle) * scale;
    const double s = std::sin(angle) * scale;
    return {c * v.x + s * v.y, -s * v.x + c * v.y};
  }

  // The pose whose apply() undoes this one's.
  [[nodiscard]] Pose2D inverse() const {
    const double c = std::cos(angle) / scale;
    const double s = std::sin(angle) / scale;
    // p = R(-a)/s * (q - t), R(-a) = [[c, -s], [s, c]] (before dividing by scale)
    return {-(c * x - s * y), -(s * x + c * y), -angle, 1.0 / scale};
  }

  // (this ∘ other)(p) = this.apply(other.apply(p))
  [[nodiscard]] Pose2D compose(const Pose2D& other) const {
    const cv::Point2d t = apply({other.x, other.y});
    return {t.x, t.y, wrapAngle(angle + other.angle), scale * other.scale};
  }
};

}  // namespace facet
