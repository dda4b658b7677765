// Why an M-estimator and not least squares on the pairs within a fixed distance: no homography
// fits a real lens's view exactly (distortion differs between zoom and focus settings), so
// the pairs' errors about the best H are a smooth field of a pixel or so, plus the wrong pairs.
// A fixed tight gate then keeps the part of the view the current H already fits and the fit
// leans to it; a wide one lets wrong pairs pull. The Cauchy loss at the pairs' own scale weighs
// every pair by its agreement, smoothly, and needs no threshold.
#include "algorithms/registration/robust_homography.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>

#include <Eigen/Dense>

#include "algorithms/geometry/levenberg_marquardt.hpp"
#include "algorithms/geometry/point_normaliser.hpp"
#include "algorithms/geometry/projective_map.hpp"

namespace facet {
namespace {

// The Cauchy loss's scale in units of the noise: 95 % efficiency on Gaussian errors.
constexpr double kCauchyScale = 2.385;
constexpr int kMaxSteps = 20;

using Params = Eigen::Matrix<double, 8, 1>;

cv::Matx33d toMatrix(const Params& h) {
  return {h(0), h(1), h(2), h(3), h(4), h(5), h(6), h(7), 1.0};
}

// r' L r: the squared transfer error in the pair's own metric.
double quadratic(const cv::Matx22d& L, cv::Point2d r) {
  return L(0, 0) * r.x * r.x + 2 * L(0, 1) * r.x * r.y + L(1, 1) * r.y * r.y;
}

double weightedCost(const Params& h, const std::vector<cv::Point2d>& a,
                    const std::vector<cv::Point2d>& b, const std::vector<cv::Matx22d>& metric,
                    const std::vector<double>& w) {
  const cv::Matx33d H = toMatrix(h);
  double cost = 0;
  for (std::size_t i = 0; i < a.size(); ++i)
    cost += w[i] * quadratic(metric[i], mapPoint(H, a[i]) - b[i]);
  return std::isfinite(cost) ? cost : std::numeric_limits<double>::infinity();
}

// J' W J and J' W r of sum w_i r_i' M_i r_i (r_i = H a_i - b_i) at h.
void normalEquations(const Params& h, const std::vector<cv::Point2d>& a,
                     const std::vector<cv::Point2d>& b, const std::vector<cv::Matx22d>& metric,
                     const std::vector<double>& w, Eigen::Matrix<double, 8, 8>& jtj, Params& jtr) {
  jtj.setZero();
  jtr.setZero();
  for (std::size_t i = 0; i < a.size(); ++i) {
    const double x = a[i].x, y = a[i].y;
    const double den = h(6) * x + h(7) * y + 1.0;
    if (std::abs(den) < 1e-12) continue;
    const double u = (h(0) * x + h(1) * y + h(2)) / den;
    const double v = (h(3) * x + h(4) * y + h(5)) / den;
    Eigen::Matrix<double, 2, 8> J;
    J << x / den, y / den, 1 / den, 0, 0, 0, -u * x / den, -u * y / den,  //
        0, 0, 0, x / den, y / den, 1 / den, -v * x / den, -v * y / den;
    const Eigen::Vector2d r(u - b[i].x, v - b[i].y);
    Eigen::Matrix2d M;
    M << metric[i](0, 0), metric[i](0, 1), metric[i](1, 0), metric[i](1, 1);
    jtj.noalias() += w[i] * J.transpose() * M * J;
    jtr.noalias() += w[i] * J.transpose() * M * r;
  }
}

// The pairs' noise scale about H: from the median transfer error in the pairs' metric.
double noiseScale(const Params& h, const std::vector<cv::Point2d>& a,
                  const std::vector<cv::Point2d>& b, const std::vector<cv::Matx22d>& metric,
                  std::vector<double>& errors) {
  const cv::Matx33d H = toMatrix(h);
  errors.resize(a.size());
  for (std::size_t i = 0; i < a.size(); ++i)
    errors[i] = std::sqrt(std::max(0.0, quadratic(metric[i], mapPoint(H, a[i]) - b[i])));
  std::vector<double> sorted = errors;
  std::nth_element(sorted.begin(), sorted.begin() + sorted.size() / 2, sorted.end());
  return sorted[sorted.size() / 2] / std::sqrt(2 * std::log(2.0));
}

// Each pair's error has two parts: its location's noise, shaped by its correlation peak
// (spread_i), and what no homography follows, the same for every pair (a lens's distortion, the
// scene's relief): covariance a * spread_i + b * I. Which of the two dominates differs from view
// to view (an exact warp has none of the second; a zoom lens much), so the ratio b / a is the
// one of a grid that makes the pairs' errors about H most likely (Gaussian, the scale a at its
// maximum-likelihood value), on the pairs within three noise scales. The metrics are the
// inverse covariances.
std::vector<cv::Matx22d> pairMetrics(const Params& h, const std::vector<cv::Point2d>& a,
                                     const std::vector<cv::Point2d>& b,
                                     const std::vector<cv::Matx22d>& spread) {
  const cv::Matx33d H = toMatrix(h);
  std::vector<cv::Point2d> r(a.size());
  std::vector<double> length(a.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    r[i] = mapPoint(H, a[i]) - b[i];
    length[i] = std::hypot(r[i].x, r[i].y);
  }
  std::vector<double> sorted = length;
  std::nth_element(sorted.begin(), sorted.begin() + sorted.size() / 2, sorted.end());
  const double core = 3 * sorted[sorted.size() / 2] / std::sqrt(2 * std::log(2.0));
  const auto covariance = [&](std::size_t i, double ratio) {
    return std::isinf(ratio) ? cv::Matx22d::eye() : spread[i] + ratio * cv::Matx22d::eye();
  };
  double bestRatio = std::numeric_limits<double>::infinity(), best = -1e300;
  for (int k = -7; k <= 7; ++k) {
    const double ratio = k == 7 ? std::numeric_limits<double>::infinity() : std::pow(10.0, k / 2.0);
    double mahalanobis = 0, logDet = 0;
    int n = 0;
    for (std::size_t i = 0; i < a.size(); ++i) {
      if (!(length[i] <= core)) continue;
      const cv::Matx22d c = covariance(i, ratio);
      mahalanobis += quadratic(c.inv(), r[i]);
      logDet += std::log(cv::determinant(c));
      ++n;
    }
    if (n < 8 || !(mahalanobis > 0)) continue;
    const double scale = mahalanobis / (2 * n);
    const double likelihood = -n * std::log(scale) - 0.5 * logDet;
    if (likelihood > best) {
      best = likelihood;
      bestRatio = ratio;
    }
  }
  std::vector<cv::Matx22d> metric(a.size());
  for (std::size_t i = 0; i < a.size(); ++i) metric[i] = covariance(i, bestRatio).inv();
  return metric;
}

}  // namespace

std::optional<RobustHomography> fitHomographyCauchy(const std::vector<cv::Point2d>& src,
                                                    const std::vector<cv::Point2d>& dst,
                                                    const cv::Matx33d& H0,
                                                    const std::vector<cv::Matx22d>& sharpness) {
  if (src.size() < 8 || src.size() != dst.size()) return std::nullopt;
  if (!sharpness.empty() && sharpness.size() != src.size()) return std::nullopt;
  // Each pair's spread (the inverse of its sharpness), scaled so that the median pair's is 1 px^2
  // a direction: the noise floor below then keeps its meaning.
  std::vector<cv::Matx22d> spread;
  if (!sharpness.empty()) {
    std::vector<double> traces;
    for (const cv::Matx22d& m : sharpness) {
      if (!(cv::determinant(m) > 0)) return std::nullopt;
      spread.push_back(m.inv());
      traces.push_back(cv::trace(spread.back()) / 2);
    }
    std::nth_element(traces.begin(), traces.begin() + traces.size() / 2, traces.end());
    const double typical = traces[traces.size() / 2];
    for (cv::Matx22d& c : spread) c *= 1.0 / typical;
  }
  std::vector<cv::Matx22d> metric(src.size(), cv::Matx22d::eye());
  const cv::Matx33d Ts = pointNormaliser(src), Td = pointNormaliser(dst);
  std::vector<cv::Point2d> a(src.size()), b(dst.size());
  for (std::size_t i = 0; i < src.size(); ++i) {
    a[i] = mapPoint(Ts, src[i]);
    b[i] = mapPoint(Td, dst[i]);
  }
  const cv::Matx33d Hn0 = Td * H0 * Ts.inv();
  if (!(std::abs(Hn0(2, 2)) > 1e-12)) return std::nullopt;
  Params h;
  for (int k = 0; k < 8; ++k) h(k) = Hn0(k / 3, k % 3) / Hn0(2, 2);

  // A floor on the scale (1e-4 px) keeps exact pairs from giving every weight but one zero.
  const double pixel = Td(0, 0), floor = 1e-4 * pixel;
  std::vector<double> errors, w(a.size());
  double sigma = floor;  // the noise scale the weights were last set at
  // Iteratively re-weighted: each Levenberg-Marquardt step starts from the metrics and Cauchy
  // weights of the pairs about the current H; the fit stops where no step lowers the cost
  // under the weights of its own H.
  const auto reweight = [&](const Params& x) {
    if (!spread.empty()) metric = pairMetrics(x, a, b, spread);
    sigma = std::max(noiseScale(x, a, b, metric, errors), floor);
    for (std::size_t i = 0; i < a.size(); ++i) {
      const double t = errors[i] / (kCauchyScale * sigma);
      w[i] = 1.0 / (1.0 + t * t);
    }
  };
  const auto cost = [&](const Params& x) { return weightedCost(x, a, b, metric, w); };
  LevenbergMarquardtCallbacks problem{
      cost,
      [&](int, const Params& x, Eigen::Matrix<double, 8, 8>& jtj, Params& jtr, double& current) {
        reweight(x);
        current = cost(x);
        normalEquations(x, a, b, metric, w, jtj, jtr);
      },
      [&](const Params& x) -> std::optional<double> {
        const double c = cost(x);
        if (!std::isfinite(c)) return std::nullopt;
        return c;
      },
      [] {}, [](int, const Params&) { return false; }};
  LevenbergMarquardtSettings settings;
  settings.maxIterations = kMaxSteps;
  reweight(h);
  if (levenbergMarquardt<8>(problem, h, settings) == LevenbergMarquardtStop::NonFiniteStep)
    return std::nullopt;
  if (!h.allFinite()) return std::nullopt;
  cv::Matx33d H = Td.inv() * toMatrix(h) * Ts;
  if (!(std::abs(H(2, 2)) > 1e-12)) return std::nullopt;
  H *= 1.0 / H(2, 2);
  RobustHomography out;
  out.H = H;
  reweight(h);
  for (std::size_t i = 0; i < a.size(); ++i)
    out.errorCovariance.push_back(metric[i].inv() * (sigma * sigma / (w[i] * pixel * pixel)));
  const std::vector<cv::Matx22d> plain(a.size(), cv::Matx22d::eye());
  out.noise = noiseScale(h, a, b, plain, errors) / pixel;
  return out;
}

}  // namespace facet
