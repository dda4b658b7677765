#include "algorithms/measure/bar_profile_fit.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

#include <Eigen/Dense>

#include "algorithms/geometry/levenberg_marquardt.hpp"

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
  using Vector7 = Eigen::Matrix<double, kUnknowns, 1>;
  using Matrix7 = Eigen::Matrix<double, kUnknowns, kUnknowns>;
  Vector7 x;
  x[kLevel] = y.front();
  x[kStep1] = first.amplitude;
  x[kStep2] = second.amplitude;
  x[kEdge1] = first.position;
  x[kEdge2] = second.position;
  x[kBlur] = std::clamp(0.5 * (first.blur + second.blur), 0.3, 4.0);
  x[kSlope] = 0.0;
  // Residuals model - data, and their sum of squares.
  const auto residuals = [&](const Vector7& v, std::vector<double>& r) {
    double sum = 0;
    for (std::size_t j = 0; j < s.size(); ++j) {
      r[j] = v[kLevel] + v[kStep1] * Phi((s[j] - v[kEdge1]) / v[kBlur]) +
             v[kStep2] * Phi((s[j] - v[kEdge2]) / v[kBlur]) + v[kSlope] * (s[j] - centre) - y[j];
      sum += r[j] * r[j];
    }
    return sum;
  };
  std::vector<double> r(s.size()), trial(s.size());
  LevenbergMarquardtCallbacks problem{
      [&](const Vector7& v) { return residuals(v, r); },
      [&](int, const Vector7& v, Matrix7& jtj, Vector7& jtr, double&) {
        jtj.setZero();
        jtr.setZero();
        Vector7 jac;
        for (std::size_t j = 0; j < s.size(); ++j) {
          const double z1 = (s[j] - v[kEdge1]) / v[kBlur], z2 = (s[j] - v[kEdge2]) / v[kBlur];
          const double g1 = std::exp(-0.5 * z1 * z1) * 0.3989422804014327;
          const double g2 = std::exp(-0.5 * z2 * z2) * 0.3989422804014327;
          jac[kLevel] = 1.0;
          jac[kStep1] = Phi(z1);
          jac[kStep2] = Phi(z2);
          jac[kEdge1] = -v[kStep1] * g1 / v[kBlur];
          jac[kEdge2] = -v[kStep2] * g2 / v[kBlur];
          jac[kBlur] = -(v[kStep1] * g1 * z1 + v[kStep2] * g2 * z2) / v[kBlur];
          jac[kSlope] = s[j] - centre;
          jtj.selfadjointView<Eigen::Lower>().rankUpdate(jac);
          jtr += jac * r[j];
        }
        jtj = jtj.selfadjointView<Eigen::Lower>();
      },
      [&](const Vector7& v) -> std::optional<double> {
        if (v[kBlur] < 0.3 || v[kBlur] > 4.0) return std::nullopt;
        return residuals(v, trial);
      },
      [&] { r.swap(trial); },
      [&](int, const Vector7& step) {
        return std::max(std::abs(step[kEdge1]), std::abs(step[kEdge2])) < 1e-7;
      }};
  LevenbergMarquardtSettings settings;
  settings.maxIterations = 50;
  settings.initialDamping = 1e-3;
  settings.maxTries = 12;
  if (levenbergMarquardt<kUnknowns>(problem, x, settings) == LevenbergMarquardtStop::NonFiniteStep)
    return std::nullopt;
  const bool sane = x.allFinite() && x[kEdge1] < x[kEdge2] && x[kEdge1] >= lo && x[kEdge2] <= hi &&
                    (x[kStep1] > 0) == (first.amplitude > 0) &&
                    (x[kStep2] > 0) == (second.amplitude > 0);
  if (!sane) return std::nullopt;
  BarEdges out{first, second};
  out.first.position = x[kEdge1], out.first.amplitude = x[kStep1], out.first.blur = x[kBlur];
  out.second.position = x[kEdge2], out.second.amplitude = x[kStep2], out.second.blur = x[kBlur];
  return out;
}

}  // namespace facet
