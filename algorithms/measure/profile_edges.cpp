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

// Exact integral of the linear interpolant of y (n samples at x0 + i h) over [lo, hi], which lie
// within the samples' span: a partial trapezoid at either end, whole ones between.
double integrate(const double* y, int n, double x0, double h, double lo, double hi) {
  const double fl = (lo - x0) / h, fh = (hi - x0) / h;
  const int il = std::clamp(static_cast<int>(std::floor(fl)), 0, n - 2);
  const int ih = std::clamp(static_cast<int>(std::floor(fh)), 0, n - 2);
  const double yl = y[il] + (fl - il) * (y[il + 1] - y[il]);
  const double yh = y[ih] + (fh - ih) * (y[ih + 1] - y[ih]);
  if (il == ih) return 0.5 * (yl + yh) * (hi - lo);
  double inner = 0;
  for (int i = il + 1; i < ih; ++i) inner += y[i] + y[i + 1];
  return 0.5 * ((yl + y[il + 1]) * (il + 1 - fl) + inner + (y[ih] + yh) * (fh - ih)) * h;
}

// Solves the 4x4 normal equations A d = r (upper triangle of A given) by Cholesky; false when A
// is not positive definite.
bool solveCholesky(const double a[10], const double r[4], double d[4]) {
  // a: (0,0) (0,1) (0,2) (0,3) (1,1) (1,2) (1,3) (2,2) (2,3) (3,3)
  const double p0 = a[0];
  if (!(p0 > 0)) return false;
  const double l00 = std::sqrt(p0);
  const double l10 = a[1] / l00, l20 = a[2] / l00, l30 = a[3] / l00;
  const double p1 = a[4] - l10 * l10;
  if (!(p1 > 0)) return false;
  const double l11 = std::sqrt(p1);
  const double l21 = (a[5] - l20 * l10) / l11, l31 = (a[6] - l30 * l10) / l11;
  const double p2 = a[7] - l20 * l20 - l21 * l21;
  if (!(p2 > 0)) return false;
  const double l22 = std::sqrt(p2);
  const double l32 = (a[8] - l30 * l20 - l31 * l21) / l22;
  const double p3 = a[9] - l30 * l30 - l31 * l31 - l32 * l32;
  if (!(p3 > 0)) return false;
  const double l33 = std::sqrt(p3);
  // L u = r, then L^T d = u.
  const double u0 = r[0] / l00;
  const double u1 = (r[1] - l10 * u0) / l11;
  const double u2 = (r[2] - l20 * u0 - l21 * u1) / l22;
  const double u3 = (r[3] - l30 * u0 - l31 * u1 - l32 * u2) / l33;
  d[3] = u3 / l33;
  d[2] = (u2 - l32 * d[3]) / l22;
  d[1] = (u1 - l21 * d[2] - l31 * d[3]) / l11;
  d[0] = (u0 - l10 * d[1] - l20 * d[2] - l30 * d[3]) / l00;
  return true;
}

// A degenerate window (flat, or too few samples on one side): the pivoting LDLT's answer.
void solveDegenerate(const double a[10], const double r[4], double d[4]) {
  Eigen::Matrix4d m;
  m << a[0], a[1], a[2], a[3], a[1], a[4], a[5], a[6], a[2], a[5], a[7], a[8], a[3], a[6], a[8],
      a[9];
  const Eigen::Vector4d x = m.ldlt().solve(Eigen::Vector4d(r[0], r[1], r[2], r[3]));
  for (int k = 0; k < 4; ++k) d[k] = x[k];
}

}  // namespace

struct ProfileEdgeFinder::Step {
  double e = 0, b = 0, w = 1, a = 0;
  bool alive = true;
  bool crowded = false;  // another step reached into its window in the first pass
};

ProfileEdgeFinder::ProfileEdgeFinder(const ProfileEdgeParams& params) : params_(params) {}
ProfileEdgeFinder::~ProfileEdgeFinder() = default;

// Gaussian first derivative of the profile, grey levels per pixel.
void ProfileEdgeFinder::derivative(const GreyProfile& p) {
  const int n = static_cast<int>(p.values.size());
  const double sigmaSamples = std::max(0.5, params_.smoothing / p.step);
  const int r = static_cast<int>(std::ceil(3.0 * sigmaSamples));
  if (p.step != kernelStep_ || kernel_.empty()) {
    kernel_.assign(r + 1, 0.0);
    kernelNorm_ = 0;
    for (int j = 1; j <= r; ++j) {
      kernel_[j] = j * std::exp(-0.5 * j * j / (sigmaSamples * sigmaSamples));
      kernelNorm_ += kernel_[j] * 2.0 * j * p.step;
    }
    kernelStep_ = p.step;
  }
  // The profile with its end samples repeated r times either side: no tap needs a clamp.
  padded_.resize(n + 2 * r);
  std::fill_n(padded_.begin(), r, p.values.front());
  std::copy(p.values.begin(), p.values.end(), padded_.begin() + r);
  std::fill_n(padded_.begin() + r + n, r, p.values.back());
  const double* v = padded_.data() + r;
  const double* w = kernel_.data();
  // Tap by tap over the whole profile (each position still sums its taps in order): the inner
  // loop has no carried sum and runs on vector lanes.
  slope_.assign(n, 0.0);
  double* d = slope_.data();
  for (int j = 1; j <= r; ++j) {
    const double wj = w[j];
    for (int i = 0; i < n; ++i) d[i] += wj * (v[i + j] - v[i - j]);
  }
  for (int i = 0; i < n; ++i) d[i] /= kernelNorm_;
}

// The live steps whose blur reaches into the window of step `self`.
void ProfileEdgeFinder::findNear(std::size_t self) {
  near_.clear();
  for (std::size_t k = 0; k < steps_.size(); ++k)
    if (k != self && steps_[k].alive &&
        std::abs(steps_[k].e - steps_[self].e) < params_.window + 6 * steps_[k].w)
      near_.push_back(k);
}

// The other steps' contribution at s, as it appears inside step `self`'s window: steps ahead add
// their rising part, steps behind subtract the part of their step not yet completed.
double ProfileEdgeFinder::neighbours(std::size_t self, double s) const {
  double sum = 0;
  for (std::size_t k : near_) {
    const double z = (s - steps_[k].e) / steps_[k].w;
    if (std::abs(z) > 8) continue;
    sum += steps_[k].e > steps_[self].e ? steps_[k].b * Phi(z) : steps_[k].b * (Phi(z) - 1.0);
  }
  return sum;
}

// Fits step `self` over its window; returns false when the fit degenerates.
bool ProfileEdgeFinder::fitStep(const GreyProfile& p, std::size_t self) {
  const ProfileEdgeParams& prm = params_;
  Step& st = steps_[self];
  double lo = std::max(p.start, st.e - prm.window);
  double hi = std::min(p.end(), st.e + prm.window);
  for (std::size_t k : near_) {
    const double mid = 0.5 * (steps_[k].e + st.e);
    if (steps_[k].e < st.e) lo = std::max(lo, mid);
    if (steps_[k].e > st.e) hi = std::min(hi, mid);
  }
  const int i0 = static_cast<int>(std::ceil((lo - p.start) / p.step - 1e-9));
  const int i1 = static_cast<int>(std::floor((hi - p.start) / p.step + 1e-9));
  if (i1 - i0 + 1 < 6) return false;
  // The window and one sample either side ([e - R, e + R] of the area balance stays within
  // [lo, hi]), with the neighbours' steps removed.
  const int j0 = std::max(0, i0 - 1), j1 = std::min<int>(p.values.size() - 1, i1 + 1);
  window_.resize(j1 - j0 + 1);
  for (int j = j0; j <= j1; ++j)
    window_[j - j0] = near_.empty() ? p.values[j] : p.values[j] - neighbours(self, p.positionAt(j));
  const double* y = window_.data() + (i0 - j0);
  const int count = i1 - i0 + 1;

  // Gauss-Newton on (a, b, e, w), started with the linear fit of (a, b) at the current e, w.
  // The normal equations keep their upper triangle only.
  double a = st.a, b = st.b, e = st.e, w = std::clamp(st.w, 0.3, 3.0);
  for (int it = 0; it < 8; ++it) {
    double jtj[10] = {}, jtr[4] = {};
    const bool levelsOnly = it == 0;
    GaussianSweep gauss((p.positionAt(i0) - e) / w, p.step / w, count);
    if (levelsOnly) {
      // Jacobian (1, f, 0, 0): the levels alone, the other two unknowns held by unit pivots.
      for (int j = 0; j < count; ++j) {
        const auto [z, density] = gauss.next();
        const double f = normal(z, density).cdf;
        const double r = y[j] - (a + b * f);
        jtj[0] += 1.0, jtj[1] += f, jtj[4] += f * f;
        jtr[0] += r, jtr[1] += f * r;
      }
      jtj[7] = jtj[9] = 1.0;
    } else {
      const double slope = -b / w;  // the model's derivative in e is slope * phi(z)
      for (int j = 0; j < count; ++j) {
        const auto [z, density] = gauss.next();
        const auto [g, f] = normal(z, density);
        const double je = slope * g, jw = je * z;
        const double r = y[j] - (a + b * f);
        jtj[0] += 1.0, jtj[1] += f, jtj[2] += je, jtj[3] += jw;
        jtj[4] += f * f, jtj[5] += f * je, jtj[6] += f * jw;
        jtj[7] += je * je, jtj[8] += je * jw, jtj[9] += jw * jw;
        jtr[0] += r, jtr[1] += f * r, jtr[2] += je * r, jtr[3] += jw * r;
      }
    }
    double d[4];
    if (!solveCholesky(jtj, jtr, d)) solveDegenerate(jtj, jtr, d);
    if (!(std::isfinite(d[0]) && std::isfinite(d[1]) && std::isfinite(d[2]) && std::isfinite(d[3])))
      return false;
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

  // Balance the area about the mid level m over [e - R, e + R] (see the header).
  const double m = a + 0.5 * b;
  for (double& v : window_) v -= m;
  double gainRadius = -1, gain = 0;
  for (int it = 0; it < 4; ++it) {
    const double r = std::min({prm.areaHalfWidth, e - lo, hi - e});
    if (r < 0.5) break;
    const double area = integrate(window_.data(), static_cast<int>(window_.size()),
                                  p.positionAt(j0), p.step, e - r, e + r);
    if (r != gainRadius) gain = b * (2.0 * Phi(r / w) - 1.0), gainRadius = r;
    const double shift = std::clamp(area / gain, -0.5, 0.5);
    e -= shift;
    if (std::abs(shift) < 1e-6) break;
  }
  st.e = e;
  return e >= lo && e <= hi;
}

const std::vector<ProfileEdge>& ProfileEdgeFinder::find(const GreyProfile& p) {
  const ProfileEdgeParams& prm = params_;
  edges_.clear();
  const int n = static_cast<int>(p.values.size());
  if (n < 6) return edges_;
  derivative(p);
  const std::vector<double>& d = slope_;
  // A blurred step of height b peaks in the derivative at b / (sqrt(2 pi) sigma_total).
  const double toStep = std::sqrt(2.0 * M_PI) * std::sqrt(prm.smoothing * prm.smoothing + 1.0);
  const int reach = std::max(1, static_cast<int>(std::lround(prm.smoothing / p.step)));
  steps_.clear();
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
    steps_.push_back(st);
  }
  // Two passes: the second fits each step with its neighbours' fitted steps removed; steps too
  // weak or degenerate after the first pass no longer count as neighbours.
  for (int pass = 0; pass < 2; ++pass) {
    for (std::size_t i = 0; i < steps_.size(); ++i) {
      if (!steps_[i].alive) continue;
      findNear(i);
      if (pass == 0) steps_[i].crowded = !near_.empty();
      // Alone in both passes: the second fit would repeat the first.
      if (pass == 1 && near_.empty() && !steps_[i].crowded) continue;
      if (!fitStep(p, i) || std::abs(steps_[i].b) < prm.minAmplitude) steps_[i].alive = false;
    }
  }
  found_.clear();
  for (const Step& st : steps_)
    if (st.alive) found_.push_back({st.e, st.b, st.w});
  std::sort(found_.begin(), found_.end(),
            [](const ProfileEdge& x, const ProfileEdge& y) { return x.position < y.position; });
  // Two candidates that converged onto one edge: keep the stronger.
  for (const ProfileEdge& e : found_) {
    if (!edges_.empty() && e.position - edges_.back().position < 0.5 &&
        (e.amplitude > 0) == (edges_.back().amplitude > 0)) {
      if (std::abs(e.amplitude) > std::abs(edges_.back().amplitude)) edges_.back() = e;
      continue;
    }
    edges_.push_back(e);
  }
  return edges_;
}

std::vector<ProfileEdge> findProfileEdges(const GreyProfile& profile,
                                          const ProfileEdgeParams& params) {
  ProfileEdgeFinder finder(params);
  return finder.find(profile);
}

}  // namespace facet
