#include "algorithms/measure/edge_cluster_fit.hpp"

#include <algorithm>
#include <cmath>
#include <optional>
#include <span>
#include <utility>
#include <vector>

#include <Eigen/Dense>

#include "algorithms/geometry/levenberg_marquardt.hpp"
#include "algorithms/geometry/standard_normal.hpp"

namespace facet {
namespace {

// The unknowns, in this order: the level before the first edge, the n steps, the n edges, the
// common blur and the background's slope.
struct Layout {
  int n;
  [[nodiscard]] int step(int k) const { return 1 + k; }
  [[nodiscard]] int edge(int k) const { return 1 + n + k; }
  [[nodiscard]] int blur() const { return 1 + 2 * n; }
  [[nodiscard]] int slope() const { return 2 + 2 * n; }
  [[nodiscard]] int unknowns() const { return 3 + 2 * n; }
};

// Whether the single-edge estimates of two neighbouring edges see each other's model error: the
// blur of one (3 w) reaches into the span over which the other balances its area (see the
// header).
bool blursOverlap(const ProfileEdge& first, const ProfileEdge& second, double areaHalfWidth) {
  const double blur = std::max(first.blur, second.blur);
  return std::abs(second.position - first.position) < 3.0 * blur + areaHalfWidth;
}

// Fits the cluster `starts` (two or more edges in axis order, each with a start position,
// amplitude and blur) over its span and up to `window` pixels beyond its end edges, short of the
// midpoint to any edge of `others` (the profile's other edges, whose fitted steps are subtracted
// first). The edges keep their order and polarity; they report the common blur. Empty when the
// fit degenerates or leaves the span.
std::optional<std::vector<ProfileEdge>> fitEdgeCluster(const GreyProfile& p,
                                                       std::span<const ProfileEdge> starts,
                                                       std::span<const ProfileEdge> others,
                                                       double window) {
  const int n = static_cast<int>(starts.size());
  if (n < 2) return std::nullopt;
  for (int k = 0; k + 1 < n; ++k)
    if (!(starts[k].position < starts[k + 1].position)) return std::nullopt;
  const Layout at{n};
  const double firstEdge = starts.front().position, lastEdge = starts.back().position;
  const double centre = 0.5 * (firstEdge + lastEdge);
  double lo = std::max(p.start, firstEdge - window);
  double hi = std::min(p.end(), lastEdge + window);
  for (const ProfileEdge& o : others) {
    if (o.position < firstEdge) lo = std::max(lo, 0.5 * (o.position + firstEdge));
    if (o.position > lastEdge) hi = std::min(hi, 0.5 * (o.position + lastEdge));
  }
  const int i0 = static_cast<int>(std::ceil((lo - p.start) / p.step - 1e-9));
  const int i1 = static_cast<int>(std::floor((hi - p.start) / p.step + 1e-9));
  if (i1 - i0 + 1 < 2 * at.unknowns()) return std::nullopt;
  std::vector<double> s(i1 - i0 + 1), y(i1 - i0 + 1);
  for (int i = i0; i <= i1; ++i) {
    s[i - i0] = p.positionAt(i);
    y[i - i0] = p.values[i];
    for (const ProfileEdge& o : others)
      y[i - i0] -= neighbourStep(o.position, o.amplitude, std::max(o.blur, 0.3), centre, s[i - i0]);
  }

  // Levenberg-Marquardt from the starts; the level before the cluster from the window's first
  // sample.
  using Vector = Eigen::VectorXd;
  using Matrix = Eigen::MatrixXd;
  Vector x(at.unknowns());
  x[0] = y.front();
  double blurSum = 0;
  for (int k = 0; k < n; ++k) {
    x[at.step(k)] = starts[k].amplitude;
    x[at.edge(k)] = starts[k].position;
    blurSum += starts[k].blur;
  }
  x[at.blur()] = std::clamp(blurSum / n, 0.3, 4.0);
  x[at.slope()] = 0.0;
  // The model at v: residuals model - data and their sum of squares, with every sample's Phi and
  // phi of every edge kept for the normal equations (computed once per evaluated point: a trial
  // that is accepted is the next iteration's point). An edge farther than kReach blurs from a
  // sample is a constant there (its Phi differs from 0 or 1 by < 1e-15).
  constexpr double kReach = 8.0;
  struct Evaluation {
    std::vector<double> r, cdf, density;
  };
  const std::size_t m = s.size();
  const auto evaluate = [&](const Vector& v, Evaluation& ev) {
    ev.r.resize(m), ev.cdf.resize(m * n), ev.density.resize(m * n);
    const double w = v[at.blur()];
    double sum = 0;
    for (std::size_t j = 0; j < m; ++j) {
      double model = v[0] + v[at.slope()] * (s[j] - centre);
      for (int k = 0; k < n; ++k) {
        const double z = (s[j] - v[at.edge(k)]) / w;
        const standard_normal::Normal nz = std::abs(z) > kReach
                                               ? standard_normal::Normal{0.0, z > 0 ? 1.0 : 0.0}
                                               : standard_normal::normal(z);
        ev.cdf[j * n + k] = nz.cdf, ev.density[j * n + k] = nz.density;
        model += v[at.step(k)] * nz.cdf;
      }
      ev.r[j] = model - y[j];
      sum += ev.r[j] * ev.r[j];
    }
    return sum;
  };
  Evaluation current, trial;
  Matrix jacobian(m, at.unknowns());
  LevenbergMarquardtCallbacks problem{
      [&](const Vector& v) { return evaluate(v, current); },
      [&](int, const Vector& v, Matrix& jtj, Vector& jtr, double&) {
        const double w = v[at.blur()];
        for (std::size_t j = 0; j < m; ++j) {
          auto row = jacobian.row(static_cast<Eigen::Index>(j));
          row[0] = 1.0;
          row[at.blur()] = 0.0;
          for (int k = 0; k < n; ++k) {
            const double z = (s[j] - v[at.edge(k)]) / w;
            const double g = current.density[j * n + k];
            row[at.step(k)] = current.cdf[j * n + k];
            row[at.edge(k)] = -v[at.step(k)] * g / w;
            row[at.blur()] -= v[at.step(k)] * g * z / w;
          }
          row[at.slope()] = s[j] - centre;
        }
        jtj.noalias() = jacobian.transpose() * jacobian;
        jtr.noalias() = jacobian.transpose() * Eigen::Map<const Vector>(current.r.data(), m);
      },
      [&](const Vector& v) -> std::optional<double> {
        if (v[at.blur()] < 0.3 || v[at.blur()] > 4.0) return std::nullopt;
        return evaluate(v, trial);
      },
      [&] { std::swap(current, trial); },
      [&](int, const Vector& step) {
        return step.segment(at.edge(0), n).cwiseAbs().maxCoeff() < 1e-7;
      }};
  LevenbergMarquardtSettings settings;
  settings.maxIterations = 50;
  settings.initialDamping = 1e-3;
  settings.maxTries = 12;
  if (levenbergMarquardt<Eigen::Dynamic>(problem, x, settings) ==
      LevenbergMarquardtStop::NonFiniteStep)
    return std::nullopt;
  if (!x.allFinite() || x[at.edge(0)] < lo || x[at.edge(n - 1)] > hi) return std::nullopt;
  const bool clipped = p.clippedWithin(i0, i1);  // ProfileEdge::clipped
  std::vector<ProfileEdge> out(starts.begin(), starts.end());
  for (int k = 0; k < n; ++k) {
    out[k].clipped = clipped;
    if ((k + 1 < n && !(x[at.edge(k)] < x[at.edge(k + 1)])) ||
        (x[at.step(k)] > 0) != (starts[k].amplitude > 0))
      return std::nullopt;
    out[k].position = x[at.edge(k)];
    out[k].amplitude = x[at.step(k)];
    out[k].blur = x[at.blur()];
  }
  return out;
}

// A step that no object can make: larger than the sensor's range (GreyProfile::clipLevel), with a
// fifth for noise and shading. For the joint fit the profile's span is no bound: the joint model
// describes narrow bars, whose steps are rightly larger than the span (2.6 times for 2 px under
// blur 2).
bool beyondSensor(const ProfileEdge& e, double clipLevel) {
  return std::abs(e.amplitude) > 1.2 * clipLevel;
}

// A single-edge fit that failed: a step well beyond the grey values the profile spans, with
// another peak within its window (`peaks` in axis order). The inner edges of a comb finer than
// its blur fit as two opposite steps of 1000-7000 grey levels on one place, cancelling; milder
// failures overshoot by twice the true step. The steps of a bar narrower than its blur do exceed
// the span (it never reaches its level), but those edges crowd anyway, and their joint fit starts
// from the derivative's peaks instead. A lone edge keeps its fit whatever its step: where the
// profile ends within its blur (a line's station at the image's border) the step rightly exceeds
// the span -- but never the sensor's range (beyondSensor), which no fit may.
bool failedFit(const ProfileEdge& e, double span, const std::vector<ProfileEdge>& peaks,
               double window, double clipLevel) {
  if (beyondSensor(e, clipLevel)) return true;
  if (!(std::abs(e.amplitude) > 1.5 * span)) return false;
  const auto near = std::count_if(peaks.begin(), peaks.end(), [&](const ProfileEdge& p) {
    return std::abs(p.position - e.position) < window;
  });
  return near >= 2;
}

// The most edges fitted together: a comb of six teeth. The joint fit's cost grows with the cube of
// its edges; a longer chain of crowded edges is fitted in overlapping blocks (fitLongChain).
constexpr std::size_t kMaxClusterEdges = 12;

// A chain of more crowded edges than one fit takes (a comb of many teeth, a row of connector
// pins): blocks of consecutive edges, each fitted together with kOverlap edges either side (at
// most kMaxClusterEdges in all) and the rest of the chain's current estimates subtracted; a block
// keeps only its own edges, which so see their neighbours modelled, not cut off at a window's
// end. Twice over (the first pass subtracts the starts, the second the first pass's fits). Steps
// then weaker than the minimum amplitude are left out. Empty when a fit fails or makes a step
// beyond the sensor's range.
constexpr std::size_t kOverlap = 2;
std::optional<std::vector<ProfileEdge>> fitLongChain(const GreyProfile& profile,
                                                     const std::vector<ProfileEdge>& starts,
                                                     const std::vector<ProfileEdge>& others,
                                                     const ProfileEdgeParams& params) {
  const std::size_t n = starts.size(), kept = kMaxClusterEdges - 2 * kOverlap;
  const std::size_t blocks = (n + kept - 1) / kept;
  std::vector<ProfileEdge> current = starts;
  const auto at = [&](std::size_t i) { return current.begin() + static_cast<std::ptrdiff_t>(i); };
  for (int pass = 0; pass < 2; ++pass)
    for (std::size_t b = 0; b < blocks; ++b) {
      const std::size_t b0 = b * n / blocks, b1 = (b + 1) * n / blocks;
      const std::size_t f0 = b0 >= kOverlap ? b0 - kOverlap : 0, f1 = std::min(n, b1 + kOverlap);
      std::vector<ProfileEdge> rest = others;
      rest.insert(rest.end(), current.begin(), at(f0));
      rest.insert(rest.end(), at(f1), current.end());
      const std::span<const ProfileEdge> fitted(current.data() + f0, f1 - f0);
      const auto fit = fitEdgeCluster(profile, fitted, rest, params.window);
      if (!fit) return std::nullopt;
      for (const ProfileEdge& e : *fit)
        if (beyondSensor(e, profile.clipLevel)) return std::nullopt;
      std::copy(fit->begin() + static_cast<std::ptrdiff_t>(b0 - f0),
                fit->begin() + static_cast<std::ptrdiff_t>(b1 - f0), at(b0));
    }
  std::erase_if(current,
                [&](const ProfileEdge& e) { return std::abs(e.amplitude) < params.minAmplitude; });
  return current;
}

// The usual profile, whose every peak gave a plausible fit and no two of whose edges crowd: the
// single fits are the answer (what the general path below gives then), found without building
// anything.
bool noneCrowd(const std::vector<ProfileEdge>& single, const std::vector<ProfileEdge>& peaks,
               double span, double clipLevel, const ProfileEdgeParams& params) {
  if (single.size() != peaks.size()) return false;
  for (std::size_t k = 0; k < single.size(); ++k) {
    if (failedFit(single[k], span, peaks, params.window, clipLevel) ||
        (single[k].amplitude > 0) != (peaks[k].amplitude > 0) ||
        !(std::abs(single[k].position - peaks[k].position) < 1.0))
      return false;
    if (k == 0) continue;
    ProfileEdge before = single[k - 1], here = single[k];
    before.position = peaks[k - 1].position, here.position = peaks[k].position;
    if (blursOverlap(before, here, params.areaHalfWidth)) return false;
  }
  return true;
}

}  // namespace

std::vector<ProfileEdge> refitCrowdedEdges(const GreyProfile& profile,
                                           const std::vector<ProfileEdge>& single,
                                           const std::vector<ProfileEdge>& peaks,
                                           const ProfileEdgeParams& params) {
  const auto [lo, hi] = std::minmax_element(profile.values.begin(), profile.values.end());
  const double span = *hi - *lo;
  if (noneCrowd(single, peaks, span, profile.clipLevel, params)) return single;
  std::vector<ProfileEdge> plausible;
  for (const ProfileEdge& e : single)
    if (!failedFit(e, span, peaks, params.window, profile.clipLevel)) plausible.push_back(e);
  // A peak without a fit starts with the blur typical of the profile's plausible fits.
  std::vector<double> blurs;
  for (const ProfileEdge& e : plausible) blurs.push_back(e.blur);
  double typicalBlur = 1.0;
  if (!blurs.empty()) {
    std::nth_element(blurs.begin(), blurs.begin() + blurs.size() / 2, blurs.end());
    typicalBlur = blurs[blurs.size() / 2];
  }

  struct Member {
    ProfileEdge anchor;   // where the edge shows: its peak, or a fit's own position
    ProfileEdge start;    // the joint fit's start: the peak's fit, else the peak
    bool peak = false;    // a peak (a start of the joint fit); else a fit that came from none
    bool fitted = false;  // `start` is a plausible single-edge fit
  };
  std::vector<Member> members;
  std::vector<bool> taken(plausible.size(), false);
  for (ProfileEdge pk : peaks) {
    pk.blur = typicalBlur;
    Member m{pk, pk, true, false};
    std::size_t from = plausible.size();
    double nearest = 1.0;
    for (std::size_t k = 0; k < plausible.size(); ++k) {
      const double d = std::abs(plausible[k].position - pk.position);
      if (!taken[k] && (plausible[k].amplitude > 0) == (pk.amplitude > 0) && d < nearest)
        nearest = d, from = k;
    }
    if (from < plausible.size()) {
      taken[from] = true;
      m.start = plausible[from];
      m.anchor.blur = plausible[from].blur;
      m.fitted = true;
    }
    // A peak weaker than an edge with no fit of its own is texture or noise: a joint fit would
    // only leave it out again (on a textured surface, chains of such peaks made clusters of
    // dozens).
    if (!m.fitted && std::abs(pk.amplitude) < params.minAmplitude) continue;
    members.push_back(m);
  }
  for (std::size_t k = 0; k < plausible.size(); ++k)
    if (!taken[k]) members.push_back({plausible[k], plausible[k], false, true});
  std::sort(members.begin(), members.end(),
            [](const Member& a, const Member& b) { return a.anchor.position < b.anchor.position; });

  // Neighbours are one cluster where their blurs overlap, or where one is a peak whose single
  // fit failed (degenerated, died or came out too weak) and the other lay within its window: the
  // failure is what a neighbour does to a single fit. A peak whose fit came out too weak is left
  // out again when the joint fit finds it weak too.
  const auto crowded = [&](const Member& a, const Member& b) {
    const bool failed = (a.peak && !a.fitted) || (b.peak && !b.fitted);
    return blursOverlap(a.anchor, b.anchor, params.areaHalfWidth) ||
           (failed && b.anchor.position - a.anchor.position < params.window);
  };
  std::vector<ProfileEdge> out;
  for (std::size_t i = 0; i < members.size();) {
    std::size_t j = i + 1;
    while (j < members.size() && crowded(members[j - 1], members[j])) ++j;
    std::vector<ProfileEdge> starts, fits;
    for (std::size_t k = i; k < j; ++k) {
      if (members[k].peak) starts.push_back(members[k].start);
      if (members[k].fitted) fits.push_back(members[k].start);
    }
    std::vector<ProfileEdge> others;
    for (std::size_t k = 0; k < members.size(); ++k)
      if ((k < i || k >= j) && members[k].fitted) others.push_back(members[k].start);
    std::optional<std::vector<ProfileEdge>> joint;
    if (starts.size() > kMaxClusterEdges) joint = fitLongChain(profile, starts, others, params);
    while (starts.size() >= 2 && starts.size() <= kMaxClusterEdges) {
      joint = fitEdgeCluster(profile, starts, others, params.window);
      if (!joint) break;
      const auto [weakest, strongest] = std::minmax_element(
          joint->begin(), joint->end(), [](const ProfileEdge& a, const ProfileEdge& b) {
            return std::abs(a.amplitude) < std::abs(b.amplitude);
          });
      // One start too many lets two steps grow huge and cancel: the larger goes first.
      const auto dropped = beyondSensor(*strongest, profile.clipLevel)          ? strongest
                           : std::abs(weakest->amplitude) < params.minAmplitude ? weakest
                                                                                : joint->end();
      if (dropped == joint->end()) break;
      starts.erase(starts.begin() + (dropped - joint->begin()));
      joint.reset();
    }
    const std::vector<ProfileEdge>& kept = joint ? *joint : fits;
    out.insert(out.end(), kept.begin(), kept.end());
    i = j;
  }
  std::sort(out.begin(), out.end(),
            [](const ProfileEdge& a, const ProfileEdge& b) { return a.position < b.position; });
  return out;
}

}  // namespace facet
