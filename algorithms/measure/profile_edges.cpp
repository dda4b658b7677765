#include "algorithms/measure/profile_edges.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <utility>

#include <Eigen/Dense>

#include "algorithms/geometry/spd_solve.hpp"
#include "algorithms/geometry/standard_normal.hpp"

namespace facet {
namespace {

using standard_normal::normal;

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

// The step fit's window reaches at least this far (pixels, and at most `window`) whatever lies
// beyond the edge; faint steps stop it beyond (ProfileEdgeFinder::fitStep).
constexpr double kCoreWindow = 4.0;
// The faintest step (grey levels, 8-bit scale) that stops a window, however clean the profile.
constexpr double kFaintStep = 2.0;

// The step fit's unknowns: the level before the edge, the step, the edge, its width, and the
// background's slope along the profile.
constexpr int kUnknowns = 5;
using Normal5 = Eigen::Matrix<double, kUnknowns, kUnknowns>;
using Vector5 = Eigen::Matrix<double, kUnknowns, 1>;

// Solves the normal equations A d = r (upper triangle of A filled) by Cholesky; a degenerate
// window (flat, or too few samples on one side) gets the pivoting LDLT's answer.
Vector5 solveNormal(const Normal5& a, const Vector5& r) {
  std::array<std::array<double, kUnknowns>, kUnknowns> lower;
  std::array<double, kUnknowns> d;
  for (int i = 0; i < kUnknowns; ++i) {
    d[i] = r[i];
    for (int j = 0; j <= i; ++j) lower[i][j] = a(j, i);
  }
  if (solveSpd<kUnknowns>(lower, d)) return Vector5(d.data());
  return a.selfadjointView<Eigen::Upper>().ldlt().solve(r);
}

}  // namespace

struct ProfileEdgeFinder::Step {
  double e = 0, b = 0, w = 1, a = 0;  // a: the background level at e, before the step
  double g = 0;                       // the background's slope, grey levels per pixel
  bool alive = true;                  // fitted: a neighbour that the other steps' fits subtract
  bool reported = false;              // and strong enough to be an edge
  bool crowded = false;               // another step reached into its window in the first pass
  bool clipped = false;               // its window holds samples the sensor clipped
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
  for (std::size_t k : near_)
    sum += neighbourStep(steps_[k].e, steps_[k].b, steps_[k].w, steps_[self].e, s);
  return sum;
}

// Fits step `self` over its window; returns false when the fit degenerates.
bool ProfileEdgeFinder::fitStep(const GreyProfile& p, std::size_t self) {
  const ProfileEdgeParams& prm = params_;
  Step& st = steps_[self];
  double lo = std::max(p.start, st.e - prm.window);
  double hi = std::min(p.end(), st.e + prm.window);
  // A faint step stops the window before its blur begins, but not within the core.
  const double core = std::min(prm.window, kCoreWindow), blurReach = 3.0 * std::max(st.w, 0.5);
  for (double f : faint_) {
    if (f > st.e) hi = std::min(hi, std::max(f - blurReach, st.e + core));
    if (f < st.e) lo = std::max(lo, std::min(f + blurReach, st.e - core));
  }
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
  // Whether the sensor clipped the profile within the window (ProfileEdge::clipped).
  st.clipped = p.clippedWithin(i0, i1);

  // Gauss-Newton on (a, b, e, w, g): the model a + b Phi((s - e) / w) + g (s - s0), started with
  // the linear fit of the levels and slope at the current e, w. The slope is shading: where the
  // window is cut short on one side, a model with flat levels would read it as a shift of the
  // edge. It is measured from s0, the edge's start, so that it does not move with e.
  const double s0 = st.e;
  // The fit stops once e and w move by less than this; with the symmetric balance after it, the
  // fit's e is only a start and what the balance needs are the levels, converged long before.
  const double converged = prm.symmetricRefinement ? 1e-3 : 1e-5;
  double a = st.a, b = st.b, e = st.e, w = std::clamp(st.w, 0.3, 3.0), g = st.g;
  for (int it = 0; it < 8; ++it) {
    const bool levelsOnly = it == 0;
    GaussianSweep gauss((p.positionAt(i0) - e) / w, p.step / w, count);
    const double slope = -b / w;  // the model's derivative in e is slope * phi(z)
    // The normal equations' upper triangle, summed in scalars (the compiler keeps them in
    // registers): Jacobian (1, f, je, jw, t); the first round fits the levels and slope alone.
    double s11 = 0, sf = 0, se = 0, sw = 0, s1t = 0, sff = 0, sfe = 0, sfw = 0, sft = 0, see = 0,
           sew = 0, set = 0, sww = 0, swt = 0, stt = 0;
    double r1 = 0, rf = 0, re = 0, rw = 0, rt = 0;
    if (levelsOnly) {
      for (int j = 0; j < count; ++j) {
        const auto [z, density] = gauss.next();
        const double f = normal(z, density).cdf;
        const double t = p.positionAt(i0 + j) - s0;
        const double r = y[j] - (a + b * f + g * t);
        s11 += 1.0, sf += f, s1t += t, sff += f * f, sft += f * t, stt += t * t;
        r1 += r, rf += f * r, rt += t * r;
      }
    } else {
      for (int j = 0; j < count; ++j) {
        const auto [z, density] = gauss.next();
        const auto [phi, f] = normal(z, density);
        const double t = p.positionAt(i0 + j) - s0;
        const double je = slope * phi, jw = je * z;
        const double r = y[j] - (a + b * f + g * t);
        s11 += 1.0, sf += f, se += je, sw += jw, s1t += t;
        sff += f * f, sfe += f * je, sfw += f * jw, sft += f * t;
        see += je * je, sew += je * jw, set += je * t;
        sww += jw * jw, swt += jw * t, stt += t * t;
        r1 += r, rf += f * r, re += je * r, rw += jw * r, rt += t * r;
      }
    }
    Normal5 jtj;
    jtj << s11, sf, se, sw, s1t, 0, sff, sfe, sfw, sft, 0, 0, see, sew, set, 0, 0, 0, sww, swt, 0,
        0, 0, 0, stt;
    const Vector5 jtr{r1, rf, re, rw, rt};
    if (levelsOnly) jtj(2, 2) = jtj(3, 3) = 1.0;  // e and w held by unit pivots
    const Vector5 d = solveNormal(jtj, jtr);
    if (!d.allFinite()) return false;
    a += d[0], b += d[1], g += d[4];
    if (!levelsOnly) {
      e += std::clamp(d[2], -1.0, 1.0);
      w = std::clamp(w + d[3], 0.3, 3.0);
    }
    if (e < lo || e > hi) return false;
    if (!levelsOnly && std::abs(d[2]) < converged && std::abs(d[3]) < converged) break;
  }
  a += g * (e - s0);  // the level at the edge
  st.a = a, st.b = b, st.w = w, st.e = e, st.g = g;
  if (!prm.symmetricRefinement) return true;

  // Balance the area about the mid line m(s) = a + b/2 + g (s - e) over [e - R, e + R] (see the
  // header).
  for (int j = j0; j <= j1; ++j) window_[j - j0] -= a + 0.5 * b + g * (p.positionAt(j) - e);
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
  candidates_.clear();
  const int n = static_cast<int>(p.values.size());
  if (n < 6) return edges_;
  derivative(p);
  const std::vector<double>& d = slope_;
  // A blurred step of height b peaks in the derivative at b / (sqrt(2 pi) sigma_total).
  const double toStep = std::sqrt(2.0 * M_PI) * std::sqrt(prm.smoothing * prm.smoothing + 1.0);
  const int reach = std::max(1, static_cast<int>(std::lround(prm.smoothing / p.step)));
  // The noise of the derivative, in step units, from its median magnitude (the profile is
  // mostly flat between its edges): peaks above 4 sigmas of it (and 2 grey levels) are steps.
  // A window no wider than the core has nothing for faint steps to stop.
  double faintStep = 0.5 * prm.minAmplitude;
  if (prm.window > kCoreWindow) {
    magnitudes_.resize(n);
    for (int i = 0; i < n; ++i) magnitudes_[i] = std::abs(d[i]);
    std::nth_element(magnitudes_.begin(), magnitudes_.begin() + n / 2, magnitudes_.end());
    faintStep = std::max(4.0 * 1.4826 * magnitudes_[n / 2] * toStep, kFaintStep);
  }
  steps_.clear();
  faint_.clear();
  for (int i = 1; i + 1 < n; ++i) {
    const double v = std::abs(d[i]);
    if (v * toStep < std::min(faintStep, 0.5 * prm.minAmplitude)) continue;
    bool peak = true;
    for (int k = 1; k <= reach && peak; ++k) {
      if (i - k >= 0 && std::abs(d[i - k]) > v) peak = false;
      if (i + k < n && std::abs(d[i + k]) >= v) peak = false;
    }
    if (!peak || d[i] * d[i - 1] < 0 || d[i] * d[i + 1] < 0) continue;
    if (v * toStep < 0.5 * prm.minAmplitude) {
      faint_.push_back(p.positionAt(i));
      continue;
    }
    // Parabola through the peak for a subpixel start.
    const double l = std::abs(d[i - 1]), r = std::abs(d[i + 1]);
    const double den = l - 2 * v + r;
    const double off = den < 0 ? std::clamp(0.5 * (l - r) / den, -0.5, 0.5) : 0.0;
    Step st;
    st.e = p.positionAt(i + off);
    st.b = d[i] * toStep;
    st.a = p.values[std::max(0, i - static_cast<int>(2.0 / p.step))];
    steps_.push_back(st);
    candidates_.push_back({st.e, st.b, 0.0, false});
  }
  // Two passes: the second fits each step with its neighbours' fitted steps removed; steps whose
  // fit degenerated in the first pass no longer count as neighbours.
  for (int pass = 0; pass < 2; ++pass) {
    for (std::size_t i = 0; i < steps_.size(); ++i) {
      if (!steps_[i].alive) continue;
      findNear(i);
      if (pass == 0) steps_[i].crowded = !near_.empty();
      // Alone in both passes: the second fit would repeat the first.
      if (pass == 1 && near_.empty() && !steps_[i].crowded) continue;
      // A step whose fit fails is no neighbour, but still stops the others' windows; one too
      // weak to be an edge is still subtracted from theirs.
      if (!fitStep(p, i)) {
        steps_[i].alive = false;
        faint_.push_back(steps_[i].e);
        continue;
      }
      steps_[i].reported = std::abs(steps_[i].b) >= prm.minAmplitude;
    }
  }
  found_.clear();
  for (const Step& st : steps_)
    if (st.alive && st.reported) found_.push_back({st.e, st.b, st.w, st.clipped});
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
