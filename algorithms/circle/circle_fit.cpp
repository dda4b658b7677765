#include "algorithms/circle/circle_fit.hpp"

#include <algorithm>
#include <cmath>
#include <memory>
#include <numbers>

#include <Eigen/Dense>

#include "algorithms/geometry/levenberg_marquardt.hpp"

namespace facet::circle_fit {
namespace {

constexpr double kPi = std::numbers::pi;

// Weighted geometric (orthogonal distance) fit by Levenberg-Marquardt: minimises
// sum w_i (|p_i - c| - R)^2 over (cx, cy, R). The offsets and distances of a trial are kept for
// the normal equations at it once it is accepted: one pass of square roots per iteration. They
// are left uninitialised (every pass writes them all before reading): zeroing them cost more than
// a pass.
class GeometricCircleFit {
 public:
  GeometricCircleFit(const std::vector<Eigen::Vector2d>& pts, const std::vector<double>& w)
      : pts_(pts),
        w_(w),
        current_(std::make_unique_for_overwrite<Offset[]>(pts.size())),
        trial_(std::make_unique_for_overwrite<Offset[]>(pts.size())) {}

  double cost(const Eigen::Vector3d& x) { return evaluate(x, current_.get()); }
  // J^T W J (its lower triangle, mirrored: the step's LDLT reads no more) and J^T W r, with the
  // Jacobian row j = (-dx / n, -dy / n, -1): each sum accumulates (w j_a) j_b in the points'
  // order, as the outer product w j j^T did.
  void normalEquations(int, const Eigen::Vector3d& x, Eigen::Matrix3d& jtj, Eigen::Vector3d& jtr,
                       double&) const {
    double h00 = 0, h10 = 0, h11 = 0, h20 = 0, h21 = 0, h22 = 0, g0 = 0, g1 = 0, g2 = 0;
    const double radius = x.z();
    for (std::size_t i = 0; i < pts_.size(); ++i) {
      const Offset& o = current_[i];
      const double n = o.distance, w = w_[i];
      if (n < 1e-12 || w == 0.0) continue;
      const double j0 = -o.dx / n, j1 = -o.dy / n;
      const double r = n - radius;
      const double wj0 = w * j0, wj1 = w * j1, wj2 = -w;
      h00 += wj0 * j0;
      h10 += wj1 * j0;
      h11 += wj1 * j1;
      h20 += wj2 * j0;
      h21 += wj2 * j1;
      h22 += w;  // (w j2) j2 with j2 = -1
      g0 += wj0 * r;
      g1 += wj1 * r;
      g2 += wj2 * r;
    }
    jtj << h00, h10, h20, h10, h11, h21, h20, h21, h22;
    jtr << g0, g1, g2;
  }
  std::optional<double> trialCost(const Eigen::Vector3d& x) { return evaluate(x, trial_.get()); }
  void accept() { std::swap(current_, trial_); }
  bool converged(int, const Eigen::Vector3d& step) const {
    // Pixels: a step of 1e-4 px leaves one of about 1e-6 px (near the fit the steps shrink
    // roughly quadratically), far below the edge points' own precision (1e-2 px); 1e-5 cost a
    // last iteration per fit that changed no printed digit of the accuracy tables.
    return step.norm() < 1e-4;
  }

 private:
  struct Offset {
    double dx, dy;    // p_i - c
    double distance;  // |p_i - c|
  };
  double evaluate(const Eigen::Vector3d& x, Offset* out) const {
    const double cx = x.x(), cy = x.y(), radius = x.z();
    double s = 0;
    for (std::size_t i = 0; i < pts_.size(); ++i) {
      const double dx = pts_[i].x() - cx, dy = pts_[i].y() - cy;
      const double n = std::sqrt(dx * dx + dy * dy);
      out[i] = {dx, dy, n};
      const double r = n - radius;
      s += w_[i] * r * r;
    }
    return s;
  }

  const std::vector<Eigen::Vector2d>& pts_;
  const std::vector<double>& w_;
  std::unique_ptr<Offset[]> current_, trial_;
};

}  // namespace

std::optional<Circle> circleThrough(const Eigen::Vector2d& a, const Eigen::Vector2d& b,
                                    const Eigen::Vector2d& c) {
  const Eigen::Vector2d ab = b - a, ac = c - a;
  const double d = 2.0 * (ab.x() * ac.y() - ab.y() * ac.x());
  if (std::abs(d) < 1e-9 * ab.squaredNorm() * ac.norm() + 1e-12) return std::nullopt;
  const double ab2 = ab.squaredNorm(), ac2 = ac.squaredNorm();
  const Eigen::Vector2d o{(ac.y() * ab2 - ab.y() * ac2) / d, (ab.x() * ac2 - ac.x() * ab2) / d};
  return Circle{a + o, o.norm()};
}

double robustWeight(CircleRobustWeight kind, double r, double sigma) {
  const double a = std::abs(r);
  switch (kind) {
    case CircleRobustWeight::Huber: {
      const double k = 1.345 * sigma;
      return a <= k ? 1.0 : k / a;
    }
    case CircleRobustWeight::Tukey: {
      const double k = 4.685 * sigma;
      if (a >= k) return 0.0;
      const double u = 1.0 - (a / k) * (a / k);
      return u * u;
    }
    case CircleRobustWeight::None:
      break;
  }
  return 1.0;
}

std::optional<Circle> fitGeometric(const std::vector<Eigen::Vector2d>& pts,
                                   const std::vector<double>& w, Circle c) {
  GeometricCircleFit problem(pts, w);
  Eigen::Vector3d x{c.centre.x(), c.centre.y(), c.radius};
  if (levenbergMarquardt(problem, x) == LevenbergMarquardtStop::NonFiniteStep) return std::nullopt;
  c = {x.head<2>(), x.z()};
  if (!c.centre.allFinite() || !std::isfinite(c.radius) || c.radius <= 0.0) return std::nullopt;
  return c;
}

double coverageDeg(const std::vector<Eigen::Vector2d>& pts, const Circle& c) {
  if (pts.size() < 2) return 0.0;
  std::vector<double> a;
  a.reserve(pts.size());
  for (const auto& p : pts) a.push_back(std::atan2(p.y() - c.centre.y(), p.x() - c.centre.x()));
  std::sort(a.begin(), a.end());
  return coverageDeg(a, c.radius);
}

double coverageDeg(const std::vector<double>& a, double radius) {
  if (a.size() < 2) return 0.0;
  const double maxGap = std::max(3.0 / std::max(radius, 1e-6), 2.0 * kPi / 180.0);
  double uncovered = 0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    const double gap = i + 1 < a.size() ? a[i + 1] - a[i] : a.front() + 2.0 * kPi - a.back();
    if (gap > maxGap) uncovered += gap;
  }
  return std::clamp(360.0 - uncovered * 180.0 / kPi, 0.0, 360.0);
}
}  // namespace facet::circle_fit
