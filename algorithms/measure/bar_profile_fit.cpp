#include "algorithms/measure/bar_profile_fit.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

#include "algorithms/geometry/spd_solve.hpp"

namespace facet {
namespace {

// Unknowns: the level before the first edge, the two steps, the two edges, the common blur and
// the background's slope.
constexpr int kUnknowns = 7;
enum { kLevel, kStep1, kStep2, kEdge1, kEdge2, kBlur, kSlope };

double Phi(double z) {
  return 0.5 * std::erfc(-z * M_SQRT1_2);
}

// Another edge's step as it appears in the window (the convention of ProfileEdgeFinder: edges
// ahead add their rising part, edges behind subtract the part not yet completed).
double otherStep(const ProfileEdge& o, double centre, double s) {
  const double z = (s - o.position) / std::max(o.blur, 0.3);
  if (std::abs(z) > 8) return 0.0;
  return o.position > centre ? o.amplitude * Phi(z) : o.amplitude * (Phi(z) - 1.0);
}

}  // namespace

bool blursOverlap(const ProfileEdge& first, const ProfileEdge& second, double areaHalfWidth) {
  const double blur = std::max(first.blur, second.blur);
  return std::abs(second.position - first.position) < 3.0 * blur + areaHalfWidth;
}

std::optional<BarEdges> fitBarProfile(const GreyProfile& p, const ProfileEdge& first,
                                      const ProfileEdge& second,
                                      std::span<const ProfileEdge> others, double window) {
  if (!(first.position < second.position) || (first.amplitude > 0) == (second.amplitude > 0))
    return std::nullopt;
  const double centre = 0.5 * (first.position + second.position);
  double lo = std::max(p.start, first.position - window);
  double hi = std::min(p.end(), second.position + window);
  for (const ProfileEdge& o : others) {
    if (o.position < first.position) lo = std::max(lo, 0.5 * (o.position + first.position));
    if (o.position > second.position) hi = std::min(hi, 0.5 * (o.position + second.position));
  }
  const int i0 = static_cast<int>(std::ceil((lo - p.start) / p.step - 1e-9));
  const int i1 = static_cast<int>(std::floor((hi - p.start) / p.step + 1e-9));
  if (i1 - i0 + 1 < 2 * kUnknowns) return std::nullopt;
  std::vector<double> s(i1 - i0 + 1), y(i1 - i0 + 1);
  for (int i = i0; i <= i1; ++i) {
    s[i - i0] = p.positionAt(i);
    y[i - i0] = p.values[i];
    for (const ProfileEdge& o : others) y[i - i0] -= otherStep(o, centre, s[i - i0]);
  }

  // Levenberg-Marquardt from the single-edge fits; the level before the bar from the window's
  // first samples.
  std::array<double, kUnknowns> x{};
  x[kLevel] = y.front();
  x[kStep1] = first.amplitude;
  x[kStep2] = second.amplitude;
  x[kEdge1] = first.position;
  x[kEdge2] = second.position;
  x[kBlur] = std::clamp(0.5 * (first.blur + second.blur), 0.3, 4.0);
  x[kSlope] = 0.0;
  const auto residuals = [&](const std::array<double, kUnknowns>& v, std::vector<double>& r) {
    double sum = 0;
    for (std::size_t j = 0; j < s.size(); ++j) {
      const double m = v[kLevel] + v[kStep1] * Phi((s[j] - v[kEdge1]) / v[kBlur]) +
                       v[kStep2] * Phi((s[j] - v[kEdge2]) / v[kBlur]) + v[kSlope] * (s[j] - centre);
      r[j] = y[j] - m;
      sum += r[j] * r[j];
    }
    return sum;
  };
  std::vector<double> r(s.size()), trial(s.size());
  double cost = residuals(x, r), lambda = 1e-3;
  for (int it = 0; it < 50; ++it) {
    std::array<std::array<double, kUnknowns>, kUnknowns> jtj{};
    std::array<double, kUnknowns> jtr{};
    for (std::size_t j = 0; j < s.size(); ++j) {
      const double z1 = (s[j] - x[kEdge1]) / x[kBlur], z2 = (s[j] - x[kEdge2]) / x[kBlur];
      const double g1 = std::exp(-0.5 * z1 * z1) * 0.3989422804014327;
      const double g2 = std::exp(-0.5 * z2 * z2) * 0.3989422804014327;
      std::array<double, kUnknowns> jac;
      jac[kLevel] = 1.0;
      jac[kStep1] = Phi(z1);
      jac[kStep2] = Phi(z2);
      jac[kEdge1] = -x[kStep1] * g1 / x[kBlur];
      jac[kEdge2] = -x[kStep2] * g2 / x[kBlur];
      jac[kBlur] = -(x[kStep1] * g1 * z1 + x[kStep2] * g2 * z2) / x[kBlur];
      jac[kSlope] = s[j] - centre;
      for (int a = 0; a < kUnknowns; ++a) {
        jtr[a] += jac[a] * r[j];
        for (int b = 0; b <= a; ++b) jtj[a][b] += jac[a] * jac[b];
      }
    }
    bool improved = false;
    while (lambda < 1e8) {
      auto a = jtj;
      auto d = jtr;
      for (int k = 0; k < kUnknowns; ++k) a[k][k] *= 1.0 + lambda;
      if (!solveSpd<kUnknowns>(a, d)) {
        lambda *= 10;
        continue;
      }
      std::array<double, kUnknowns> next = x;
      for (int k = 0; k < kUnknowns; ++k) next[k] += d[k];
      if (next[kBlur] < 0.3 || next[kBlur] > 4.0) {
        lambda *= 10;
        continue;
      }
      const double nextCost = residuals(next, trial);
      if (nextCost <= cost) {
        const double move = std::max(std::abs(d[kEdge1]), std::abs(d[kEdge2]));
        x = next, cost = nextCost, r.swap(trial);
        lambda = std::max(lambda / 10, 1e-9);
        improved = true;
        if (move < 1e-7) it = 50;  // converged
        break;
      }
      lambda *= 10;
    }
    if (!improved) break;
  }
  const bool sane = std::isfinite(cost) && x[kEdge1] < x[kEdge2] && x[kEdge1] >= lo &&
                    x[kEdge2] <= hi && (x[kStep1] > 0) == (first.amplitude > 0) &&
                    (x[kStep2] > 0) == (second.amplitude > 0);
  if (!sane) return std::nullopt;
  BarEdges out{first, second};
  out.first.position = x[kEdge1], out.first.amplitude = x[kStep1], out.first.blur = x[kBlur];
  out.second.position = x[kEdge2], out.second.amplitude = x[kStep2], out.second.blur = x[kBlur];
  return out;
}

}  // namespace facet
