#include "algorithms/circle/circle_fit.hpp"

#include <algorithm>
#include <cmath>
#include <memory>
#include <numbers>

#include <Eigen/Dense>

#include "algorithms/circle/pixel_pass.hpp"
#include "algorithms/geometry/levenberg_marquardt.hpp"

namespace facet::circle_fit {
namespace {

constexpr double kPi = std::numbers::pi;

// The offsets (dx, dy) of n points (x, y) from the centre (cx, cy), their distances and the
// terms w (distance - radius)^2 of the cost, elementwise: a pass of its own so that it vectorises
// (the cost's sum stays in the points' order, below).
FACET_PIXEL_PASS void offsetsFrom(std::ptrdiff_t n, const double* __restrict x,
                                  const double* __restrict y, const double* __restrict w, double cx,
                                  double cy, double radius, double* __restrict dx,
                                  double* __restrict dy, double* __restrict distance,
                                  double* __restrict cost) {
  for (std::ptrdiff_t i = 0; i < n; ++i) {
    dx[i] = x[i] - cx;
    dy[i] = y[i] - cy;
    distance[i] = std::sqrt(dx[i] * dx[i] + dy[i] * dy[i]);
    const double r = distance[i] - radius;
    cost[i] = w[i] * r * r;
  }
}

// The columns of the per-point terms of J^T W J and J^T W r.
struct NormalTerms {
  double *h00, *h10, *h11, *h20, *h21, *h22, *g0, *g1, *g2;
};

// Each point's terms of J^T W J and J^T W r (w j_a j_b and w j_a r, Jacobian row
// j = (-dx / n, -dy / n, -1)), +0.0 for a point at the centre or of weight 0; elementwise, so
// that it vectorises (the columns handed one by one: the compiler does not vectorise stores
// through pointers it cannot tell apart).
FACET_PIXEL_PASS void normalTerms(std::ptrdiff_t n, const double* __restrict dx,
                                  const double* __restrict dy, const double* __restrict distance,
                                  const double* __restrict w, double radius, double* __restrict h00,
                                  double* __restrict h10, double* __restrict h11,
                                  double* __restrict h20, double* __restrict h21,
                                  double* __restrict h22, double* __restrict g0,
                                  double* __restrict g1, double* __restrict g2) {
  for (std::ptrdiff_t i = 0; i < n; ++i) {
    const double d = distance[i];
    const bool used = !(d < 1e-12 || w[i] == 0.0);
    const double j0 = -dx[i] / d, j1 = -dy[i] / d;
    const double r = d - radius;
    const double wj0 = w[i] * j0, wj1 = w[i] * j1, wj2 = -w[i];
    h00[i] = used ? wj0 * j0 : 0.0;
    h10[i] = used ? wj1 * j0 : 0.0;
    h11[i] = used ? wj1 * j1 : 0.0;
    h20[i] = used ? wj2 * j0 : 0.0;
    h21[i] = used ? wj2 * j1 : 0.0;
    h22[i] = used ? w[i] : 0.0;  // (w j2) j2 with j2 = -1
    g0[i] = used ? wj0 * r : 0.0;
    g1[i] = used ? wj1 * r : 0.0;
    g2[i] = used ? wj2 * r : 0.0;
  }
}

// Weighted geometric (orthogonal distance) fit by Levenberg-Marquardt: minimises
// sum w_i (|p_i - c| - R)^2 over (cx, cy, R). The offsets and distances of a trial are kept for
// the normal equations at it once it is accepted: one pass of square roots per iteration. The
// per-point work is done in elementwise passes over columns; the sums then add the terms in the
// points' order, as a single loop did (a skipped point's term is +0.0, which leaves a sum as it
// is: a sum from +0.0 is never -0.0). The columns are left uninitialised (every pass writes them
// all before reading): zeroing them cost more than a pass.
class GeometricCircleFit {
 public:
  GeometricCircleFit(const std::vector<Eigen::Vector2d>& pts, const std::vector<double>& w)
      : n_(static_cast<std::ptrdiff_t>(pts.size())),
        w_(w),
        x_(std::make_unique_for_overwrite<double[]>(pts.size())),
        y_(std::make_unique_for_overwrite<double[]>(pts.size())),
        current_(std::make_unique_for_overwrite<double[]>(3 * pts.size())),
        trial_(std::make_unique_for_overwrite<double[]>(3 * pts.size())),
        scratch_(std::make_unique_for_overwrite<double[]>(9 * pts.size())) {
    for (std::ptrdiff_t i = 0; i < n_; ++i) {
      x_[i] = pts[static_cast<std::size_t>(i)].x();
      y_[i] = pts[static_cast<std::size_t>(i)].y();
    }
  }

  double cost(const Eigen::Vector3d& x) { return evaluate(x, current_.get()); }
  // J^T W J (its lower triangle, mirrored: the step's LDLT reads no more) and J^T W r, each sum
  // accumulating (w j_a) j_b in the points' order, as the outer product w j j^T did.
  void normalEquations(int, const Eigen::Vector3d& x, Eigen::Matrix3d& jtj, Eigen::Vector3d& jtr,
                       double&) const {
    const double* o = current_.get();
    double* s = scratch_.get();
    const NormalTerms t{s,          s + n_,     s + 2 * n_, s + 3 * n_, s + 4 * n_,
                        s + 5 * n_, s + 6 * n_, s + 7 * n_, s + 8 * n_};
    normalTerms(n_, o, o + n_, o + 2 * n_, w_.data(), x.z(), t.h00, t.h10, t.h11, t.h20, t.h21,
                t.h22, t.g0, t.g1, t.g2);
    double h00 = 0, h10 = 0, h11 = 0, h20 = 0, h21 = 0, h22 = 0, g0 = 0, g1 = 0, g2 = 0;
    for (std::ptrdiff_t i = 0; i < n_; ++i) {
      h00 += t.h00[i];
      h10 += t.h10[i];
      h11 += t.h11[i];
      h20 += t.h20[i];
      h21 += t.h21[i];
      h22 += t.h22[i];
      g0 += t.g0[i];
      g1 += t.g1[i];
      g2 += t.g2[i];
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
  // The offsets at x into `out` (columns dx, dy, distance); the cost.
  double evaluate(const Eigen::Vector3d& x, double* out) const {
    double* terms = scratch_.get();
    offsetsFrom(n_, x_.get(), y_.get(), w_.data(), x.x(), x.y(), x.z(), out, out + n_, out + 2 * n_,
                terms);
    double s = 0;
    for (std::ptrdiff_t i = 0; i < n_; ++i) s += terms[i];
    return s;
  }

  std::ptrdiff_t n_;
  const std::vector<double>& w_;
  std::unique_ptr<double[]> x_, y_;            // the points' coordinates
  std::unique_ptr<double[]> current_, trial_;  // offsets: dx, dy, distance (n each)
  std::unique_ptr<double[]> scratch_;          // the terms of the sums
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
