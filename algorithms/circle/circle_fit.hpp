#pragma once
// Geometric (orthogonal-distance) circle fitting of rim edge points: the circle through three
// points for RANSAC, the robust weights, the weighted Levenberg-Marquardt fit and the angular
// coverage of a point set. Used by measureCircle (circle_measure.cpp).

#include <optional>
#include <vector>

#include <Eigen/Core>

#include "algorithms/circle/circle_measure.hpp"

namespace facet::circle_fit {

struct Circle {
  Eigen::Vector2d centre;
  double radius = 0.0;
};

// Signed distance of p from the circle (positive outside).
inline double residual(const Circle& c, const Eigen::Vector2d& p) {
  return (p - c.centre).norm() - c.radius;
}

// The circle through three points, or nothing when they are (nearly) collinear.
std::optional<Circle> circleThrough(const Eigen::Vector2d& a, const Eigen::Vector2d& b,
                                    const Eigen::Vector2d& c);

// Robust weight of a residual given the scale sigma (IRLS).
double robustWeight(CircleRobustWeight kind, double r, double sigma);

// Weighted geometric fit, minimising sum w_i (|p_i - c| - R)^2 over (cx, cy, R) from `start`.
// Returns nothing when the fit does not converge to a finite circle.
std::optional<Circle> fitGeometric(const std::vector<Eigen::Vector2d>& pts,
                                   const std::vector<double>& w, Circle start);

// Angular extent covered by points around the circle's centre, degrees: 360 minus every gap
// between neighbouring points wider than a few pixels of arc (the natural spacing of edge points).
double coverageDeg(const std::vector<Eigen::Vector2d>& pts, const Circle& c);

// The same from the points' polar angles around the centre (atan2, radians), sorted, for a circle
// of `radius`: for a caller that has sorted them already.
double coverageDeg(const std::vector<double>& sortedAngles, double radius);

}  // namespace facet::circle_fit
