#include "algorithms/circle/rim_ellipse.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>

#include <Eigen/Dense>

#include "algorithms/geometry/ransac.hpp"

namespace facet::rim_ellipse {
namespace {

// The ellipse's implicit function rho = |(u / major, v / minor)| at p ((u, v): p's offset from
// the centre along the axes; 1 on the ellipse) and its gradient in the image: the residual and
// the normal both follow from one evaluation.
struct Level {
  double rho;
  Eigen::Vector2d gradient;
};

Level levelAt(const Ellipse& e, const Eigen::Vector2d& p) {
  const double c = e.axis.x(), s = e.axis.y();
  const Eigen::Vector2d d = p - e.centre;
  const double toMajor = 1.0 / e.major, toMinor = 1.0 / e.minor;
  const double x = (c * d.x() + s * d.y()) * toMajor, y = (-s * d.x() + c * d.y()) * toMinor;
  const double rho = std::max(std::sqrt(x * x + y * y), 1e-12);
  const double gu = x * toMajor / rho, gv = y * toMinor / rho;  // along the axes
  return {rho, {c * gu - s * gv, s * gu + c * gv}};
}

// The signed distance (first order) from the level: rho - 1 over the gradient's length.
double distanceOf(const Level& l, double gradientLength) {
  return (l.rho - 1.0) / gradientLength;
}

// The direct least-squares ellipse through the points (at least 6): Fitzgibbon, Pilu and
// Fisher's fit (the algebraic distance under the constraint 4AC - B^2 = 1, which only an
// ellipse meets) in Halir and Flusser's numerically stable form, on points moved to their mean
// and scaled to unit spread. Written here rather than taken from OpenCV: cv::fitEllipseDirect
// took 0.2 ms for the 600 points of an r = 100 px rim (a third of the whole measurement),
// this takes a few microseconds.
std::optional<Ellipse> fitEllipse(const std::vector<Eigen::Vector2d>& pts) {
  const auto n = static_cast<double>(pts.size());
  Eigen::Vector2d mean = Eigen::Vector2d::Zero();
  for (const auto& p : pts) mean += p;
  mean /= n;
  double spread = 0.0;
  for (const auto& p : pts) spread += (p - mean).squaredNorm();
  spread = std::sqrt(spread / n);
  if (!(spread > 0.0)) return std::nullopt;
  // The scatter of the quadratic terms (x^2, xy, y^2) and the linear ones (x, y, 1), from the
  // points' moments up to the fourth (sum[i][j]: the sum of x^i y^j).
  double sum[5][5] = {};
  const double inv = 1.0 / spread;
  for (const auto& p : pts) {
    const double x = (p.x() - mean.x()) * inv, y = (p.y() - mean.y()) * inv;
    const double xx = x * x, xy = x * y, yy = y * y;
    sum[4][0] += xx * xx;
    sum[3][1] += xx * xy;
    sum[2][2] += xx * yy;
    sum[1][3] += xy * yy;
    sum[0][4] += yy * yy;
    sum[3][0] += xx * x;
    sum[2][1] += xx * y;
    sum[1][2] += x * yy;
    sum[0][3] += yy * y;
    sum[2][0] += xx;
    sum[1][1] += xy;
    sum[0][2] += yy;
  }
  sum[0][0] = n;  // the first moments are 0: the points are about their mean
  Eigen::Matrix3d s1, s2, s3;
  s1 << sum[4][0], sum[3][1], sum[2][2], sum[3][1], sum[2][2], sum[1][3], sum[2][2], sum[1][3],
      sum[0][4];
  s2 << sum[3][0], sum[2][1], sum[2][0], sum[2][1], sum[1][2], sum[1][1], sum[1][2], sum[0][3],
      sum[0][2];
  s3 << sum[2][0], sum[1][1], 0.0, sum[1][1], sum[0][2], 0.0, 0.0, 0.0, sum[0][0];
  const Eigen::Matrix3d t = -s3.ldlt().solve(s2.transpose());  // linear = t * quadratic
  const Eigen::Matrix3d m = s1 + s2 * t;
  // The constraint's matrix inverted, applied: rows m(2) / 2, -m(1), m(0) / 2.
  Eigen::Matrix3d reduced;
  reduced.row(0) = m.row(2) / 2.0;
  reduced.row(1) = -m.row(1);
  reduced.row(2) = m.row(0) / 2.0;
  const Eigen::EigenSolver<Eigen::Matrix3d> solver(reduced);
  std::optional<Eigen::Vector3d> quadratic;
  for (int k = 0; k < 3; ++k) {
    const Eigen::Vector3d v = solver.eigenvectors().col(k).real();
    // The ellipse's eigenvector, signed so that its quadratic form is positive definite.
    if (4.0 * v(0) * v(2) - v(1) * v(1) > 0.0) quadratic = v(0) > 0.0 ? v : Eigen::Vector3d(-v);
  }
  if (!quadratic) return std::nullopt;
  const Eigen::Vector3d linear = t * *quadratic;
  // A x^2 + B xy + C y^2 + D x + E y + F = 0 in the scaled coordinates: centre, then the axes
  // from the quadratic form's eigenvalues (the smaller one's direction is the major axis).
  const double a = (*quadratic)(0), b = (*quadratic)(1), c = (*quadratic)(2);
  const double d = linear(0), e = linear(1), f = linear(2);
  Eigen::Matrix2d form;
  form << a, b / 2.0, b / 2.0, c;
  const Eigen::Vector2d centre = form.ldlt().solve(Eigen::Vector2d{-d / 2.0, -e / 2.0});
  const double value = f + (d * centre.x() + e * centre.y()) / 2.0;  // the conic at the centre
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> axes(form);
  const double l0 = axes.eigenvalues()(0), l1 = axes.eigenvalues()(1);
  if (!(-value / l0 > 0.0 && -value / l1 > 0.0)) return std::nullopt;
  Ellipse ellipse{mean + spread * centre, spread * std::sqrt(-value / l0),
                  spread * std::sqrt(-value / l1), axes.eigenvectors().col(0).normalized()};
  if (!std::isfinite(ellipse.centre.x() + ellipse.centre.y() + ellipse.major + ellipse.minor))
    return std::nullopt;
  return ellipse;
}

}  // namespace

double Ellipse::meanRadius() const {
  return std::sqrt(major * minor);
}

cv::Matx22d Ellipse::toCircle() const {
  // R diag(sqrt(minor / major), sqrt(major / minor)) R^T, R the rotation taking x to the axis.
  const double c = axis.x(), s = axis.y();
  const double along = std::sqrt(minor / major), across = std::sqrt(major / minor);
  return {along * c * c + across * s * s, (along - across) * c * s, (along - across) * c * s,
          along * s * s + across * c * c};
}

Ellipse reshaped(const Ellipse& e, double a, double c) {
  // exp(S) = cosh t I + sinh t / t S, t = sqrt(a^2 + c^2) (S^2 = t^2 I); its determinant is 1.
  const double t = std::hypot(a, c);
  const double ch = std::cosh(t), sh = t > 1e-12 ? std::sinh(t) / t : 1.0;
  Eigen::Matrix2d step, map;
  step << ch + sh * a, sh * c, sh * c, ch - sh * a;
  const cv::Matx22d m = e.toCircle();
  map << m(0, 0), m(0, 1), m(1, 0), m(1, 1);
  // The symmetric factor of step * map: the square root of (step map)^T (step map). Its smaller
  // eigenvalue's direction is shrunk most on the way to the circle: the major axis.
  const Eigen::Matrix2d product = step * map;
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> gram(product.transpose() * product);
  const double shrink = std::sqrt(gram.eigenvalues()(0)), grow = std::sqrt(gram.eigenvalues()(1));
  const double radius = e.meanRadius();  // shrink * grow = 1: the map keeps areas
  return {e.centre, radius / shrink, radius / grow, gram.eigenvectors().col(0).normalized()};
}

cv::Vec2d stretchOf(const Ellipse& e) {
  // toCircle's eigenvalues: sqrt(minor / major) along the major axis, its inverse across.
  const double along = 0.5 * std::log(e.minor / e.major), c = e.axis.x(), s = e.axis.y();
  return {along * (c * c - s * s), along * 2.0 * c * s};
}

double residual(const Ellipse& e, const Eigen::Vector2d& p) {
  const Level l = levelAt(e, p);
  return distanceOf(l, l.gradient.norm());
}

Eigen::Vector2d outwardNormal(const Ellipse& e, const Eigen::Vector2d& p) {
  return levelAt(e, p).gradient.normalized();
}

double secondHarmonicChiSquare(const std::vector<Eigen::Vector2d>& pts,
                               const circle_fit::Circle& circle) {
  if (pts.size() <= 5) return 0.0;
  Eigen::Matrix2d m = Eigen::Matrix2d::Zero();
  Eigen::Vector2d v = Eigen::Vector2d::Zero();
  double rss = 0.0;
  for (const auto& p : pts) {
    const Eigen::Vector2d d = p - circle.centre;
    const double rho2 = d.squaredNorm();
    if (rho2 == 0.0) continue;
    // cos 2phi and sin 2phi without trigonometry.
    const Eigen::Vector2d h{(d.x() * d.x() - d.y() * d.y()) / rho2, 2.0 * d.x() * d.y() / rho2};
    const double r = std::sqrt(rho2) - circle.radius;
    m += h * h.transpose();
    v += h * r;
    rss += r * r;
  }
  const Eigen::Vector2d beta = m.ldlt().solve(v);
  const double explained = v.dot(beta);
  // Five parameters in all: the circle's three and the harmonic's two.
  const double variance = (rss - explained) / static_cast<double>(pts.size() - 5);
  if (!(variance > 0.0) || !std::isfinite(explained)) return 0.0;
  return explained / variance;
}

std::optional<Fit> fitRimEllipse(const std::vector<Eigen::Vector2d>& pts,
                                 const std::vector<Eigen::Vector2d>& normals,
                                 const std::vector<Eigen::Vector2d>& seed, double threshold,
                                 double cosTolerance) {
  if (seed.size() < 6) return std::nullopt;
  std::vector<Eigen::Vector2d> fitted = seed;
  std::optional<Ellipse> ellipse;
  std::vector<std::uint8_t> taken, takenBefore;
  bool settled = false;  // the last ellipse was fitted to the points it takes in
  // Each round takes in the rim points the last ellipse reaches; a few suffice (the points a
  // circle missed on an ellipse lie within the band of the first ellipse through the others).
  for (int round = 0; round < 4; ++round) {
    ellipse = fitEllipse(fitted);
    if (!ellipse) return std::nullopt;
    std::vector<Eigen::Vector2d> in;
    taken.assign(pts.size(), 0);
    for (std::size_t i = 0; i < pts.size(); ++i) {
      const Level l = levelAt(*ellipse, pts[i]);
      const double length = l.gradient.norm();
      if (std::abs(distanceOf(l, length)) <= threshold &&
          normals[i].dot(l.gradient) >= cosTolerance * length) {
        in.push_back(pts[i]);
        taken[i] = 1;
      }
    }
    if (in.size() < 6) return std::nullopt;
    settled = taken == takenBefore;
    std::swap(taken, takenBefore);
    fitted = std::move(in);
    if (settled) break;
  }
  if (!settled) ellipse = fitEllipse(fitted);
  if (!ellipse) return std::nullopt;

  Fit fit;
  fit.ellipse = *ellipse;
  double rssEllipse = 0.0;
  for (const auto& p : fitted) rssEllipse += std::pow(residual(*ellipse, p), 2);
  const auto n = static_cast<double>(fitted.size());
  fit.rms = std::sqrt(rssEllipse / n);
  const auto circle = circle_fit::fitGeometric(fitted, std::vector<double>(fitted.size(), 1.0),
                                               {ellipse->centre, ellipse->meanRadius()});
  if (circle) {
    double rssCircle = 0.0;
    for (const auto& p : fitted) rssCircle += std::pow(circle_fit::residual(*circle, p), 2);
    fit.fStatistic = (rssCircle - rssEllipse) / 2.0 / std::max(rssEllipse / (n - 5.0), 1e-300);
  }
  fit.inliers = std::move(fitted);
  return fit;
}

std::vector<Eigen::Vector2d> ellipseConsensus(const std::vector<Eigen::Vector2d>& pts,
                                              const std::vector<Eigen::Vector2d>& normals,
                                              double threshold, double cosTolerance) {
  constexpr std::size_t kSample = 6;  // the direct fit's least number of points
  std::vector<Eigen::Vector2d> sample(kSample);
  auto agrees = [&](const Ellipse& e, std::size_t i) {
    const Level l = levelAt(e, pts[i]);
    const double length = l.gradient.norm();
    return normals[i].dot(l.gradient) >= cosTolerance * length ? std::abs(distanceOf(l, length))
                                                               : HUGE_VAL;
  };
  auto fit = [&](const std::vector<std::size_t>& drawn) -> std::optional<Ellipse> {
    for (std::size_t k = 0; k < kSample; ++k) sample[k] = pts[drawn[k]];
    std::optional<Ellipse> e = fitEllipse(sample);
    // A sample whose own points' gradients the ellipse does not follow is not the rim.
    if (e)
      for (std::size_t k : drawn)
        if (!(agrees(*e, k) <= threshold)) return std::nullopt;
    return e;
  };
  RansacParams params;
  params.inlierThreshold = threshold;
  params.maxIterations = 300;
  const auto found = ransac<Ellipse>(pts.size(), kSample, fit, agrees, params);
  std::vector<Eigen::Vector2d> consensus;
  if (!found || found->inliers.size() < kSample) return consensus;
  for (std::size_t i : found->inliers) consensus.push_back(pts[i]);
  return consensus;
}

}  // namespace facet::rim_ellipse
