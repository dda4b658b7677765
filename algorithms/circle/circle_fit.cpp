#include "algorithms/circle/circle_fit.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include <Eigen/Dense>

#include "algorithms/geometry/levenberg_marquardt.hpp"

namespace facet::circle_fit {
namespace {

constexpr double kPi = std::numbers::pi;

// Weighted geometric (orthogonal distance) fit by Levenberg-Marquardt: minimises
// sum w_i (|p_i - c| - R)^2 over (cx, cy, R). The offsets and distances of a trial are kept for
// the normal equations at it once it is accepted: one pass of square roots per iteration.
class GeometricCircleFit {
 public:
  GeometricCircleFit(const std::vector<Eigen::Vector2d>& pts, const std::vector<double>& w)
      : pts_(pts), w_(w), current_(pts.size()), trial_(pts.size()) {}

  double cost(const Eigen::Vector3d& x) { return evaluate(x, current_); }
  void normalEquations(int, const Eigen::Vector3d& x, Eigen::Matrix3d& jtj, Eigen::Vector3d& jtr,
                       double&) const {
    jtj.setZero();
    jtr.setZero();
    for (std::size_t i = 0; i < pts_.size(); ++i) {
      const Eigen::Vector2d& d = current_[i].offset;
      const double n = current_[i].distance;
      if (n < 1e-12 || w_[i] == 0.0) continue;
      const Eigen::Vector3d j{-d.x() / n, -d.y() / n, -1.0};
      const double r = n - x.z();
      jtj.noalias() += w_[i] * j * j.transpose();
      jtr.noalias() += w_[i] * j * r;
    }
  }
  std::optional<double> trialCost(const Eigen::Vector3d& x) { return evaluate(x, trial_); }
  void accept() { std::swap(current_, trial_); }
  bool converged(int, const Eigen::Vector3d& step) const {
    return step.norm() < 1e-5;  // pixels: far below the accuracy sought
  }

 private:
  struct Offset {
    Eigen::Vector2d offset;  // p_i - c
    double distance = 0;     // |p_i - c|
  };
  double evaluate(const Eigen::Vector3d& x, std::vector<Offset>& out) const {
    double s = 0;
    for (std::size_t i = 0; i < pts_.size(); ++i) {
      out[i].offset = pts_[i] - x.head<2>();
      out[i].distance = out[i].offset.norm();
      const double r = out[i].distance - x.z();
      s += w_[i] * r * r;
    }
    return s;
  }

  const std::vector<Eigen::Vector2d>& pts_;
  const std::vector<double>& w_;
  std::vector<Offset> current_, trial_;
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
