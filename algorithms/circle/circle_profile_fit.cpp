#include "algorithms/circle/circle_profile_fit.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include <Eigen/Dense>

namespace facet {
namespace {

constexpr double kPi = std::numbers::pi;

// One pixel of the band: position and grey value, with its fixed angular interpolation.
struct Sample {
  double x, y, grey;
  int k0, k1;  // sector nodes either side of the pixel's angle
  double w1;   // weight of k1 (k0 gets 1 - w1)
};

// Parameters: 0 cx, 1 cy, 2 R, 3 s, then a_k (4 + 2k) and b_k (5 + 2k) per sector node.
struct Model {
  Eigen::VectorXd p;
  int nodes = 0;
};

double medianOf(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
  return v[v.size() / 2];
}

}  // namespace

std::optional<CircleProfileFit> fitCircleProfile(const cv::Mat& image, cv::Point2d centre,
                                                 double radius,
                                                 const std::vector<cv::Point2d>& rimPoints,
                                                 double maxShift) {
  if (image.empty() || radius <= 1.0 || rimPoints.size() < 3) return std::nullopt;
  const double scale = image.depth() == CV_16U ? 1.0 / 256.0 : 1.0;

  // Angular bins of about 2 px of arc: a bin takes part when an inlier edge point lies in it.
  const int bins = std::max(16, static_cast<int>(2.0 * kPi * radius / 2.0));
  auto binOf = [&](double dx, double dy) {
    const double a = std::atan2(dy, dx) + kPi;  // 0..2pi
    return std::min(bins - 1, static_cast<int>(a / (2.0 * kPi) * bins));
  };
  std::vector<std::uint8_t> covered(bins, 0);
  for (const auto& q : rimPoints) covered[binOf(q.x - centre.x, q.y - centre.y)] = 1;

  // Sector nodes for a and b: about one per 25 px of arc, at least 4.
  const int nodes = std::clamp(static_cast<int>(2.0 * kPi * radius / 25.0), 4, 32);

  // The band |rho - R| <= 3 px inside the image.
  constexpr double kBand = 3.0;
  std::vector<Sample> samples;
  const double rOut = radius + kBand, rIn = std::max(0.0, radius - kBand);
  const int x0 = std::max(0, static_cast<int>(std::floor(centre.x - rOut)));
  const int x1 = std::min(image.cols - 1, static_cast<int>(std::ceil(centre.x + rOut)));
  const int y0 = std::max(0, static_cast<int>(std::floor(centre.y - rOut)));
  const int y1 = std::min(image.rows - 1, static_cast<int>(std::ceil(centre.y + rOut)));
  for (int y = y0; y <= y1; ++y) {
    const double dy = y - centre.y;
    for (int x = x0; x <= x1; ++x) {
      const double dx = x - centre.x;
      const double r2 = dx * dx + dy * dy;
      if (r2 < rIn * rIn || r2 > rOut * rOut || !covered[binOf(dx, dy)]) continue;
      const double grey = image.depth() == CV_16U ? image.at<std::uint16_t>(y, x) * scale
                                                  : image.at<std::uint8_t>(y, x);
      const double t = (std::atan2(dy, dx) + kPi) / (2.0 * kPi) * nodes;  // 0..nodes
      const int k0 = static_cast<int>(std::floor(t)) % nodes;
      samples.push_back({static_cast<double>(x), static_cast<double>(y), grey, k0, (k0 + 1) % nodes,
                         t - std::floor(t)});
    }
  }
  if (samples.size() < 30) return std::nullopt;

  // Start: outside and inside levels from the band's two halves, blur 1.2 px.
  std::vector<double> inside, outside;
  for (const Sample& s : samples) {
    const double d = std::hypot(s.x - centre.x, s.y - centre.y) - radius;
    if (d < -2.0) inside.push_back(s.grey);
    if (d > 2.0) outside.push_back(s.grey);
  }
  if (inside.empty() || outside.empty()) return std::nullopt;
  const double a0 = medianOf(outside), b0 = medianOf(inside) - a0;
  const int n = 4 + 2 * nodes;
  Eigen::VectorXd p(n);
  p(0) = centre.x;
  p(1) = centre.y;
  p(2) = radius;
  p(3) = 1.2;
  for (int k = 0; k < nodes; ++k) {
    p(4 + 2 * k) = a0;
    p(5 + 2 * k) = b0;
  }

  // One pass over the band at parameters q: residuals (grey - model) and Jacobian rows (8
  // non-zero entries per pixel: cx, cy, R, s, and a, b at the two sector nodes).
  const std::size_t m = samples.size();
  std::vector<double> r(m), rTry(m), jac(8 * m), jacTry(8 * m), weight(m, 1.0);
  auto evaluate = [&](const Eigen::VectorXd& q, std::vector<double>& res, std::vector<double>& j) {
    const double s = q(3), inv = 1.0 / s, norm = 1.0 / (std::sqrt(2.0 * kPi) * s);
    for (std::size_t i = 0; i < m; ++i) {
      const Sample& e = samples[i];
      const double ex = e.x - q(0), ey = e.y - q(1);
      const double rho = std::max(std::sqrt(ex * ex + ey * ey), 1e-9);
      const double d = rho - q(2);
      const double w0 = 1.0 - e.w1;
      const double a = w0 * q(4 + 2 * e.k0) + e.w1 * q(4 + 2 * e.k1);
      const double b = w0 * q(5 + 2 * e.k0) + e.w1 * q(5 + 2 * e.k1);
      const double z = d * inv;
      const double phi = 0.5 * std::erfc(z / std::numbers::sqrt2);  // Phi(-d / s)
      const double bg = b * norm * std::exp(-0.5 * z * z);          // b * pdf(d; s)
      res[i] = e.grey - (a + b * phi);
      // dI/dd = -b g; dd/dcx = -ex/rho, dd/dcy = -ey/rho, dd/dR = -1; dI/ds = b g d / s.
      double* row = &j[8 * i];
      row[0] = bg * ex / rho;
      row[1] = bg * ey / rho;
      row[2] = bg;
      row[3] = bg * z;
      row[4] = w0;
      row[5] = e.w1;
      row[6] = w0 * phi;
      row[7] = e.w1 * phi;
    }
  };
  auto cost = [&](const std::vector<double>& res) {
    double c = 0;
    for (std::size_t i = 0; i < m; ++i) c += weight[i] * res[i] * res[i];
    return c;
  };
  Eigen::MatrixXd jtj(n, n);
  Eigen::VectorXd jtr(n);
  auto normalEquations = [&] {
    jtj.setZero();
    jtr.setZero();
    double* h = jtj.data();
    for (std::size_t i = 0; i < m; ++i) {
      const double w = weight[i];
      if (w == 0.0) continue;
      const Sample& e = samples[i];
      const int cols[8] = {0, 1, 2, 3, 4 + 2 * e.k0, 4 + 2 * e.k1, 5 + 2 * e.k0, 5 + 2 * e.k1};
      const double* row = &jac[8 * i];
      for (int u = 0; u < 8; ++u) {
        const double wu = w * row[u];
        jtr(cols[u]) += wu * r[i];
        for (int v = 0; v < 8; ++v) h[cols[u] * n + cols[v]] += wu * row[v];
      }
    }
  };
  auto tukeyWeights = [&] {
    std::vector<double> absR(m);
    for (std::size_t i = 0; i < m; ++i) absR[i] = std::abs(r[i]);
    const double sigma = std::max(1.4826 * medianOf(absR), 0.25);
    const double c = 4.685 * sigma;
    for (std::size_t i = 0; i < m; ++i) {
      const double u = absR[i] / c;
      weight[i] = u >= 1.0 ? 0.0 : (1 - u * u) * (1 - u * u);
    }
    return sigma;
  };

  evaluate(p, r, jac);
  double current = cost(r);
  double sigma = 0.0;
  double lambda = 1e-4;
  for (int it = 0; it < 10; ++it) {
    // Robust weights once the grey levels have settled (after the first, linear-ish step).
    if (it == 1 || it == 3) {
      sigma = tukeyWeights();
      current = cost(r);
    }
    normalEquations();
    bool accepted = false;
    Eigen::VectorXd step;
    for (int tries = 0; tries < 6 && !accepted; ++tries) {
      Eigen::MatrixXd a = jtj;
      a.diagonal() += lambda * jtj.diagonal().cwiseMax(1e-9);
      step = a.ldlt().solve(jtr);
      if (!step.allFinite()) return std::nullopt;
      const Eigen::VectorXd next = p + step;
      if (next(3) > 0.05) {
        evaluate(next, rTry, jacTry);
        const double c = cost(rTry);
        if (c <= current) {
          accepted = true;
          p = next;
          current = c;
          std::swap(r, rTry);
          std::swap(jac, jacTry);
          lambda = std::max(lambda * 0.3, 1e-9);
          break;
        }
      }
      lambda *= 10;
    }
    if (!accepted) break;
    if (it >= 3 && step.head<4>().norm() < 1e-4) break;
  }

  const double blur = p(3);
  const cv::Point2d c{p(0), p(1)};
  if (!p.allFinite() || blur < 0.2 || blur > 5.0 || p(2) <= 0.0 ||
      std::hypot(c.x - centre.x, c.y - centre.y) > maxShift || std::abs(p(2) - radius) > maxShift)
    return std::nullopt;
  CircleProfileFit fit;
  fit.centre = c;
  fit.blur = blur;
  fit.radius = p(2) + blur * blur / (2.0 * p(2));
  fit.noise = sigma;
  fit.pixels = static_cast<int>(samples.size());
  return fit;
}

}  // namespace facet
