#include "algorithms/measure/profile_edges.hpp"

#include <algorithm>
#include <cmath>
#include <utility>

#include <Eigen/Dense>

namespace facet {
namespace {

// The standard normal density phi(z) and distribution Phi(z) from one exponential: erf by
// Abramowitz & Stegun 7.1.26 (|error| < 1.5e-7, i.e. < 1e-4 grey levels on a 255 step). The step
// fit evaluates them a few thousand times per edge; std::erfc costs several times more.
struct Normal {
  double density, cdf;
};
// From z and exp(-z^2 / 2).
Normal normal(double z, double e) {
  const double x = std::abs(z) * M_SQRT1_2;
  const double t = 1.0 / (1.0 + 0.3275911 * x);
  const double poly =
      t *
      (0.254829592 + t * (-0.284496736 + t * (1.421413741 + t * (-1.453152027 + t * 1.061405429))));
  const double half = 0.5 * poly * e;  // 0.5 * erfc(x)
  return {0.3989422804014327 * e, z >= 0 ? 1.0 - half : half};
}
Normal normal(double z) {
  return normal(z, std::exp(-0.5 * z * z));
}

// exp(-z^2 / 2) at evenly spaced z = z0 + j dz, as the step fit needs it at every sample of its
// window: each value is the last times exp(-z dz - dz^2 / 2), a ratio that shrinks by exp(-dz^2)
// per sample, so a window costs three exponentials instead of one per sample. The products'
// rounding (about 1e-14 relative over a window) is far below the erf's 1.5e-7. Where a value or
// a ratio could leave the range of normal doubles (|z| > 20 or dz > 2) every value is direct.
class GaussianSweep {
 public:
  GaussianSweep(double z0, double dz, int count) : z0_(z0), dz_(dz) {
    const double zEnd = z0 + (count - 1) * dz;
    direct_ = std::max(std::abs(z0), std::abs(zEnd)) > 20.0 || std::abs(dz) > 2.0;
    if (direct_) return;
    value_ = std::exp(-0.5 * z0 * z0);
    ratio_ = std::exp(-z0 * dz - 0.5 * dz * dz);
    shrink_ = std::exp(-dz * dz);
  }
  // z and exp(-z^2 / 2) at the next sample, the first at z0.
  std::pair<double, double> next() {
    const double z = z0_ + j_++ * dz_;
    if (direct_) return {z, std::exp(-0.5 * z * z)};
    const double value = value_;
    value_ *= ratio_, ratio_ *= shrink_;
    return {z, value};
  }

 private:
  double z0_, dz_;
  int j_ = 0;
  bool direct_ = true;
  double value_ = 0, ratio_ = 0, shrink_ = 0;
};
double Phi(double z) {
  return normal(z).cdf;
}

struct Step {
  double e = 0, b = 0, w = 1, a = 0;
  bool alive = true;
  bool crowded = false;  // another step reached into its window in the first pass
};

// Gaussian first derivative of the profile, grey levels per pixel.
std::vector<double> derivative(const GreyProfile& p, double sigma) {
  const int n = static_cast<int>(p.values.size());
  const double sigmaSamples = std::max(0.5, sigma / p.step);
  const int r = static_cast<int>(std::ceil(3.0 * sigmaSamples));
  std::vector<double> w(r + 1, 0.0);
  double norm = 0;
  for (int j = 1; j <= r; ++j) {
    w[j] = j * std::exp(-0.5 * j * j / (sigmaSamples * sigmaSamples));
    norm += w[j] * 2.0 * j * p.step;
  }
  // The profile with its end samples repeated r times either side: no tap needs a clamp.
  std::vector<double> padded(n + 2 * r);
  std::fill_n(padded.begin(), r, p.values.front());
  std::copy(p.values.begin(), p.values.end(), padded.begin() + r);
  std::fill_n(padded.begin() + r + n, r, p.values.back());
  const double* v = padded.data() + r;
  std::vector<double> d(n, 0.0);
  for (int i = 0; i < n; ++i) {
    double sum = 0;
    for (int j = 1; j <= r; ++j) sum += w[j] * (v[i + j] - v[i - j]);
    d[i] = sum / norm;
  }
  return d;
}

// The other steps' contribution at s, as it appears inside edge `self`'s window: steps ahead add
// their rising part, steps behind subtract the part of their step not yet completed.
double neighbours(const std::vector<Step>& steps, const std::vector<std::size_t>& near,
                  std::size_t self, double s) {
  double sum = 0;
  for (std::size_t k : near) {
    const double z = (s - steps[k].e) / steps[k].w;
    if (std::abs(z) > 8) continue;
    sum += steps[k].e > steps[self].e ? steps[k].b * Phi(z) : steps[k].b * (Phi(z) - 1.0);
  }
  return sum;
}

// Exact integral of the linear interpolant of y (samples at x0 + i h) over [lo, hi].
double integrate(const std::vector<double>& y, double x0, double h, double lo, double hi) {
  auto value = [&](double x) {
    const double f = (x - x0) / h;
    const int i = std::clamp(static_cast<int>(std::floor(f)), 0, static_cast<int>(y.size()) - 2);
    const double t = f - i;
    return y[i] + t * (y[i + 1] - y[i]);
  };
  double sum = 0;
  double x = lo;
  while (x < hi) {
    const double nextKnot = x0 + (std::floor((x - x0) / h + 1e-12) + 1) * h;
    const double xe = std::min(hi, nextKnot);
    sum += 0.5 * (value(x) + value(xe)) * (xe - x);
    x = xe;
  }
  return sum;
}

// Fits steps[i] over its window; returns false when the fit degenerates.
// The live steps whose blur reaches into the window of step i.
std::vector<std::size_t> nearSteps(const std::vector<Step>& steps, std::size_t i, double window) {
  std::vector<std::size_t> near;
  for (std::size_t k = 0; k < steps.size(); ++k)
    if (k != i && steps[k].alive && std::abs(steps[k].e - steps[i].e) < window + 6 * steps[k].w)
      near.push_back(k);
  return near;
}

bool fitStep(const GreyProfile& p, std::vector<Step>& steps, std::size_t i,
             const std::vector<std::size_t>& near, const ProfileEdgeParams& prm) {
  Step& st = steps[i];
  double lo = std::max(p.start, st.e - prm.window);
  double hi = std::min(p.end(), st.e + prm.window);
  for (std::size_t k : near) {
    const double mid = 0.5 * (steps[k].e + st.e);
    if (steps[k].e < st.e) lo = std::max(lo, mid);
    if (steps[k].e > st.e) hi = std::min(hi, mid);
  }
  const int i0 = static_cast<int>(std::ceil((lo - p.start) / p.step - 1e-9));
  const int i1 = static_cast<int>(std::floor((hi - p.start) / p.step + 1e-9));
  if (i1 - i0 + 1 < 6) return false;
  std::vector<double> y(i1 - i0 + 1);
  for (int j = i0; j <= i1; ++j)
    y[j - i0] = p.values[j] - neighbours(steps, near, i, p.positionAt(j));
  // Gauss-Newton on (a, b, e, w), started with the linear fit of (a, b) at the current e, w.
  double a = st.a, b = st.b, e = st.e, w = std::clamp(st.w, 0.3, 3.0);
  for (int it = 0; it < 8; ++it) {
    Eigen::Matrix4d jtj = Eigen::Matrix4d::Zero();
    Eigen::Vector4d jtr = Eigen::Vector4d::Zero();
    const bool levelsOnly = it == 0;
    GaussianSweep gauss((p.positionAt(i0) - e) / w, p.step / w, static_cast<int>(y.size()));
    for (std::size_t j = 0; j < y.size(); ++j) {
      const auto [z, density] = gauss.next();
      const auto [g, f] = normal(z, density);
      Eigen::Vector4d jac(1.0, f, -b * g / w, -b * g * z / w);
      if (levelsOnly) jac[2] = jac[3] = 0;
      const double r = y[j] - (a + b * f);
      jtj += jac * jac.transpose();
      jtr += jac * r;
    }
    if (levelsOnly) jtj(2, 2) = jtj(3, 3) = 1.0;
    // Cholesky is the cheap solve of the usual positive definite system; a degenerate window
    // (flat, or too few samples on one side) falls back to the pivoting LDLT.
    const Eigen::LLT<Eigen::Matrix4d> llt(jtj);
    const Eigen::Vector4d d =
        llt.info() == Eigen::Success ? Eigen::Vector4d(llt.solve(jtr)) : jtj.ldlt().solve(jtr);
    if (!d.allFinite()) return false;
    a += d[0], b += d[1];
    if (!levelsOnly) {
      e += std::clamp(d[2], -1.0, 1.0);
      w = std::clamp(w + d[3], 0.3, 3.0);
    }
    if (e < lo || e > hi) return false;
    if (!levelsOnly && std::abs(d[2]) < 1e-5 && std::abs(d[3]) < 1e-4) break;
  }
  st.a = a, st.b = b, st.w = w, st.e = e;
  if (!prm.symmetricRefinement) return true;

  // Balance the area about the mid level over [e - R, e + R] (see the header).
  const double m = a + 0.5 * b;
  // The window and one sample either side: [e - R, e + R] stays within [lo, hi].
  const int j0 = std::max(0, i0 - 1), j1 = std::min<int>(p.values.size() - 1, i1 + 1);
  std::vector<double> centred(j1 - j0 + 1);
  for (int j = j0; j <= j1; ++j)
    centred[j - j0] = p.values[j] - neighbours(steps, near, i, p.positionAt(j)) - m;
  for (int it = 0; it < 4; ++it) {
    const double r = std::min({prm.areaHalfWidth, e - lo, hi - e});
    if (r < 0.5) break;
    const double area = integrate(centred, p.positionAt(j0), p.step, e - r, e + r);
    const double gain = b * (2.0 * Phi(r / w) - 1.0);
    const double shift = std::clamp(area / gain, -0.5, 0.5);
    e -= shift;
    if (std::abs(shift) < 1e-6) break;
  }
  st.e = e;
  return e >= lo && e <= hi;
}

}  // namespace

std::vector<ProfileEdge> findProfileEdges(const GreyProfile& p, const ProfileEdgeParams& prm) {
  const int n = static_cast<int>(p.values.size());
  if (n < 6) return {};
  const std::vector<double> d = derivative(p, prm.smoothing);
  // A blurred step of height b peaks in the derivative at b / (sqrt(2 pi) sigma_total).
  const double toStep = std::sqrt(2.0 * M_PI) * std::sqrt(prm.smoothing * prm.smoothing + 1.0);
  const int reach = std::max(1, static_cast<int>(std::lround(prm.smoothing / p.step)));
  std::vector<Step> steps;
  for (int i = 1; i + 1 < n; ++i) {
    const double v = std::abs(d[i]);
    if (v * toStep < 0.5 * prm.minAmplitude) continue;
    bool peak = true;
    for (int k = 1; k <= reach && peak; ++k) {
      if (i - k >= 0 && std::abs(d[i - k]) > v) peak = false;
      if (i + k < n && std::abs(d[i + k]) >= v) peak = false;
    }
    if (!peak || d[i] * d[i - 1] < 0 || d[i] * d[i + 1] < 0) continue;
    // Parabola through the peak for a subpixel start.
    const double l = std::abs(d[i - 1]), r = std::abs(d[i + 1]);
    const double den = l - 2 * v + r;
    const double off = den < 0 ? std::clamp(0.5 * (l - r) / den, -0.5, 0.5) : 0.0;
    Step st;
    st.e = p.positionAt(i + off);
    st.b = d[i] * toStep;
    st.a = p.values[std::max(0, i - static_cast<int>(2.0 / p.step))];
    steps.push_back(st);
  }
  // Two passes: the second fits each step with its neighbours' fitted steps removed; steps too
  // weak or degenerate after the first pass no longer count as neighbours.
  for (int pass = 0; pass < 2; ++pass) {
    for (std::size_t i = 0; i < steps.size(); ++i) {
      if (!steps[i].alive) continue;
      const std::vector<std::size_t> near = nearSteps(steps, i, prm.window);
      if (pass == 0) steps[i].crowded = !near.empty();
      // Alone in both passes: the second fit would repeat the first.
      if (pass == 1 && near.empty() && !steps[i].crowded) continue;
      if (!fitStep(p, steps, i, near, prm) || std::abs(steps[i].b) < prm.minAmplitude)
        steps[i].alive = false;
    }
  }
  std::vector<ProfileEdge> edges;
  for (const Step& st : steps)
    if (st.alive) edges.push_back({st.e, st.b, st.w});
  std::sort(edges.begin(), edges.end(),
            [](const ProfileEdge& x, const ProfileEdge& y) { return x.position < y.position; });
  // Two candidates that converged onto one edge: keep the stronger.
  std::vector<ProfileEdge> unique;
  for (const ProfileEdge& e : edges) {
    if (!unique.empty() && e.position - unique.back().position < 0.5 &&
        (e.amplitude > 0) == (unique.back().amplitude > 0)) {
      if (std::abs(e.amplitude) > std::abs(unique.back().amplitude)) unique.back() = e;
      continue;
    }
    unique.push_back(e);
  }
  return unique;
}

}  // namespace facet
