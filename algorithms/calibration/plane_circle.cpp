#include "algorithms/calibration/plane_circle.hpp"

#include <cmath>

#include <Eigen/Dense>

namespace facet {

std::optional<PlaneCircle> fitCircle(const std::vector<cv::Point2d>& points) {
  const auto n = static_cast<Eigen::Index>(points.size());
  if (n < 3) return std::nullopt;
  // Kasa's algebraic fit as the start: x^2 + y^2 + D x + E y + F = 0, centred for conditioning.
  cv::Point2d mean(0, 0);
  for (const auto& p : points) mean += p;
  mean /= static_cast<double>(n);
  Eigen::MatrixXd A(n, 3);
  Eigen::VectorXd b(n);
  for (Eigen::Index i = 0; i < n; ++i) {
    const cv::Point2d p = points[static_cast<std::size_t>(i)] - mean;
    A.row(i) << p.x, p.y, 1.0;
    b(i) = -(p.x * p.x + p.y * p.y);
  }
  const Eigen::Vector3d k = A.colPivHouseholderQr().solve(b);
  double cx = -k(0) / 2, cy = -k(1) / 2;
  double r = std::sqrt(std::max(cx * cx + cy * cy - k(2), 0.0));
  if (!std::isfinite(r) || r <= 0) return std::nullopt;
  // Gauss-Newton on the orthogonal distances |p - c| - r (converges in a few steps from Kasa).
  Eigen::MatrixXd J(n, 3);
  Eigen::VectorXd res(n);
  for (int it = 0; it < 20; ++it) {
    for (Eigen::Index i = 0; i < n; ++i) {
      const cv::Point2d p = points[static_cast<std::size_t>(i)] - mean;
      const double dx = p.x - cx, dy = p.y - cy, d = std::hypot(dx, dy);
      if (d <= 0) return std::nullopt;
      J.row(i) << -dx / d, -dy / d, -1.0;
      res(i) = d - r;
    }
    const Eigen::Vector3d step = J.colPivHouseholderQr().solve(-res);
    cx += step(0), cy += step(1), r += step(2);
    if (step.norm() < 1e-12 * std::max(1.0, r)) break;
  }
  if (!std::isfinite(cx) || !std::isfinite(cy) || !std::isfinite(r) || r <= 0) return std::nullopt;
  PlaneCircle c;
  c.centreMm = mean + cv::Point2d(cx, cy);
  c.diameterMm = 2 * r;
  c.rmsMm = std::sqrt(res.squaredNorm() / static_cast<double>(n));
  c.roundnessMm = res.maxCoeff() - res.minCoeff();
  c.points = static_cast<int>(n);
  return c;
}

std::optional<PlaneCircle> circleInPlane(const CircleMeasurement& m, const WorldMapping& mapping) {
  if (!m.status.ok() || m.inlierPoints.size() < 3) return std::nullopt;
  // The edge points' own circle in the image, for the outward direction of each point.
  const auto edges = fitCircle(m.inlierPoints);
  if (!edges) return std::nullopt;
  // Second-derivative edges on a blurred curved rim sit k / r inside it, k = (sigma^2 + 1.2) / 2
  // for a Gaussian blur sigma (circle_measure.hpp); the grey-value fit measured sigma. (Its
  // radius cannot be used directly: it fits a circle to what may be an ellipse in the image.)
  const double k = m.greyRefined ? (m.blur * m.blur + 1.2) / 2 : CircleMeasureParams{}.radiusBiasK;
  const double shift = k / m.radius;
  std::vector<cv::Point2d> plane;
  plane.reserve(m.inlierPoints.size());
  for (const auto& p : m.inlierPoints) {
    const cv::Point2d radial = p - edges->centreMm;
    const double d = cv::norm(radial);
    const cv::Point2d q = mapping.toPlane(d > 0 ? p + radial * (shift / d) : p);
    if (!std::isfinite(q.x) || !std::isfinite(q.y)) return std::nullopt;
    plane.push_back(q);
  }
  return fitCircle(plane);
}

}  // namespace facet
