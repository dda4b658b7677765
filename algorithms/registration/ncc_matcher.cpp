#include "algorithms/registration/ncc_matcher.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <numbers>

namespace facet {
namespace {

// Bounds are computed in floating point; a candidate is abandoned only when its bound is below
// the threshold by more than this, so rounding can never discard the true best.
constexpr double kBoundSlack = 1e-6;

// Per-window quantities for one placement of its compared rows [first, first + rings).
struct Placement {
  int first = 0;
  std::int64_t sum = 0, squares = 0;
  double variance = 0;  // N * squares - sum^2 (N times the sum of squared deviations)
  double mean = 0;      // sum / N
  // For the Jensen bound, over the compared rows from r on (rings + 1 entries): their sum, and
  // their squared deviations from `mean`. They depend on the window alone, not on the pair.
  std::vector<double> restSum;
  std::vector<double> restDeviation;
  // Energy of the window minus its mean, ring effects and column effects (the two profiles are
  // orthogonal after centring): what neither projection explains.
  double interaction = 0;
  std::vector<double> ringSums;   // radius profile, rings entries
  std::vector<float> columnSums;  // angle profile, stored twice (2 * angles entries)
  double columnNorm = 0;          // |angle profile|, for the float rounding pad
  // |DFT| of the angle profile at frequencies 1..angles/2, weighted by sqrt of their multiplicity
  // (2, or 1 for angles/2) so that a plain dot product gives sum_{k=1}^{A-1} |X_k| |Y_k|.
  std::vector<double> spectrum;
};

Placement place(const LogPolarWindow& w, int first, int rings) {
  const int A = w.angles;
  Placement p;
  p.first = first;
  p.sum = w.ringSum[first + rings] - w.ringSum[first];
  p.squares = w.ringSquares[first + rings] - w.ringSquares[first];
  const auto n = static_cast<std::int64_t>(rings) * A;
  p.variance = static_cast<double>(n * p.squares - p.sum * p.sum);
  p.mean = static_cast<double>(p.sum) / static_cast<double>(n);
  p.restSum.resize(rings + 1);
  p.restDeviation.resize(rings + 1);
  for (int r = 0; r <= rings; ++r) {
    const double m = static_cast<double>(rings - r) * A;
    const double sum = static_cast<double>(w.ringSum[first + rings] - w.ringSum[first + r]);
    const double sq = static_cast<double>(w.ringSquares[first + rings] - w.ringSquares[first + r]);
    p.restSum[r] = sum;
    p.restDeviation[r] = std::max(0.0, sq - 2 * p.mean * sum + m * p.mean * p.mean);
  }
  p.ringSums.resize(rings);
  double ringEnergy = 0;
  for (int r = 0; r < rings; ++r) {
    p.ringSums[r] = static_cast<double>(w.ringSum[first + r + 1] - w.ringSum[first + r]);
    ringEnergy += p.ringSums[r] * p.ringSums[r];
  }

  p.columnSums.resize(2 * A);
  double columnEnergy = 0;
  for (int t = 0; t < A; ++t) {
    const double c = w.columnSum[(first + rings) * A + t] - w.columnSum[first * A + t];
    p.columnSums[t] = p.columnSums[t + A] = static_cast<float>(c);  // exact: integers < 2^24
    columnEnergy += c * c;
  }
  p.columnNorm = std::sqrt(columnEnergy);
  const double sum = static_cast<double>(p.sum);
  p.interaction = std::max(0.0, static_cast<double>(p.squares) - ringEnergy / A -
                                    columnEnergy / rings + sum * sum / static_cast<double>(n)) +
                  1e-9 * static_cast<double>(p.squares) + 1.0;  // pad against rounding: bound only
  std::vector<double> cosines(A), sines(A);
  for (int t = 0; t < A; ++t) {
    cosines[t] = std::cos(2.0 * std::numbers::pi * t / A);
    sines[t] = std::sin(2.0 * std::numbers::pi * t / A);
  }
  for (int k = 1; k <= A / 2; ++k) {
    double re = 0, im = 0;
    for (int t = 0; t < A; ++t) {
      re += static_cast<double>(p.columnSums[t]) * cosines[(k * t) % A];
      im -= static_cast<double>(p.columnSums[t]) * sines[(k * t) % A];
    }
    const double weight = (2 * k == A) ? 1.0 : std::sqrt(2.0);
    // Rounded up a little: the spectrum only feeds an upper bound.
    p.spectrum.push_back(weight * std::hypot(re, im) * (1 + 1e-12) + 1e-9);
  }
  return p;
}

// The image window's placements for ring shifts -S..S, computed once per window.
std::vector<Placement> placements(const LogPolarWindow& w, int rings, int S) {
  std::vector<Placement> out;
  for (int s = -S; s <= S; ++s) out.push_back(place(w, S + s, rings));
  return out;
}

// Float dot product with eight partial sums, so that the compiler can vectorise it (a single
// running sum must be added in order). Its rounding error stays below n * 2^-24 * |a| |b|.
inline float dotFloat(const float* a, const float* b, int n) {
  float acc[8] = {0, 0, 0, 0, 0, 0, 0, 0};
  int i = 0;
  for (; i + 8 <= n; i += 8)
    for (int k = 0; k < 8; ++k) acc[k] += a[i + k] * b[i + k];
  float sum = ((acc[0] + acc[4]) + (acc[1] + acc[5])) + ((acc[2] + acc[6]) + (acc[3] + acc[7]));
  for (; i < n; ++i) sum += a[i] * b[i];
  return sum;
}

using DoubleLanes = double __attribute__((vector_size(16)));

// Double dot product with four partial sums (terms i mod 4), held in two lane vectors.
inline double dotDouble(const double* a, const double* b, int n) {
  DoubleLanes acc0 = {0, 0}, acc1 = {0, 0};
  int i = 0;
  for (; i + 4 <= n; i += 4) {
    DoubleLanes x0, y0, x1, y1;
    std::memcpy(&x0, a + i, sizeof x0);
    std::memcpy(&y0, b + i, sizeof y0);
    std::memcpy(&x1, a + i + 2, sizeof x1);
    std::memcpy(&y1, b + i + 2, sizeof y1);
    acc0 += x0 * y0;
    acc1 += x1 * y1;
  }
  const DoubleLanes acc = acc0 + acc1;
  double sum = acc[0] + acc[1];
  for (; i < n; ++i) sum += a[i] * b[i];
  return sum;
}

using FloatLanes = float __attribute__((vector_size(16)));
constexpr int kLaneWidth = 4;
// Shifts correlated in one pass over the profile: eight lanes, whose sums stay in registers.
constexpr int kProfileLanes = 8;

// Cyclic correlation of two angle profiles for the shifts t0 .. t0 + 4 * lanes - 1 at once:
// out[t] = sum_i a[i] b[i + t], with `b` stored twice so that b[i + t] needs no wrap. Each shift
// is summed in order of i; its rounding error stays below n * 2^-24 * |a| |b| as for dotFloat.
template <int lanes>
inline void correlateProfileShifts(const float* a, const float* b, int n, int t0, float* out) {
  FloatLanes acc[lanes] = {};
  for (int i = 0; i < n; ++i) {
    const FloatLanes ai = {a[i], a[i], a[i], a[i]};
    for (int k = 0; k < lanes; ++k) {
      FloatLanes bk;
      std::memcpy(&bk, b + i + t0 + kLaneWidth * k, sizeof bk);
      acc[k] += ai * bk;
    }
  }
  std::memcpy(out + t0, acc, sizeof acc);
}

// out[t] = sum_i a[i] b[i + t] for every cyclic shift t in [0, n): the angle profiles'
// correlation, all shifts in a few passes instead of one dot product per shift.
inline void correlateProfiles(const float* a, const float* bTwice, int n, float* out) {
  int t = 0;
  for (; t + kLaneWidth * kProfileLanes <= n; t += kLaneWidth * kProfileLanes)
    correlateProfileShifts<kProfileLanes>(a, bTwice, n, t, out);
  for (; t + kLaneWidth <= n; t += kLaneWidth) correlateProfileShifts<1>(a, bTwice, n, t, out);
  for (; t < n; ++t) out[t] = dotFloat(a, bTwice + t, n);
}

constexpr int kDefaultAngles = LogPolarParams{}.angles;

// Rows of `fixedAngles` samples (0: the length n is known at run time only). A length known at
// compile time lets the compiler unroll the whole row.
template <int fixedAngles>
inline std::int32_t rowDot(const std::int16_t* a, const std::int16_t* b, int n) {
  if constexpr (fixedAngles > 0) n = fixedAngles;
  std::int32_t acc = 0;
  for (int i = 0; i < n; ++i) acc += static_cast<std::int32_t>(a[i]) * b[i];
  return acc;
}

struct Pair {
  const LogPolarWindow& a;
  const LogPolarWindow& b;
  const Placement& pa;  // reference placement (central rows)
  const std::vector<Placement>& pb;
  int S, R, A;
  std::int64_t N;
};

// Full NCC at ring shift index si (s = si - S) and angle shift t. Returns false when the shift
// has no defined NCC (flat window) or was abandoned by the Jensen bound below `thr`.
template <int fixedAngles>  // q.A when not 0; see rowDot
bool fullScore(const Pair& q, int si, int t, double thr, const NccAccelerations& acc,
               double& score) {
  const Placement& pb = q.pb[si];
  const int A = fixedAngles > 0 ? fixedAngles : q.A;
  std::int64_t sb = 0, sbb = 0;
  if (acc.sumTables) {
    sb = pb.sum;
    sbb = pb.squares;
  } else {
    for (int r = 0; r < q.R; ++r) {
      const std::int16_t* b = q.b.row(pb.first + r) + t;
      for (int i = 0; i < A; ++i) {
        sb += b[i];
        sbb += static_cast<std::int32_t>(b[i]) * b[i];
      }
    }
  }
  const std::int64_t varB = q.N * sbb - sb * sb;
  if (varB <= 0) return false;
  const double den = std::sqrt(q.pa.variance * static_cast<double>(varB));
  const double meanA = q.pa.mean;
  const double meanB = pb.mean;  // sb equals pb.sum with or without the sum tables
  std::int64_t sab = 0;
  for (int r = 0; r < q.R; ++r) {
    sab += rowDot<fixedAngles>(q.a.row(q.pa.first + r), q.b.row(pb.first + r) + t, A);
    if (acc.jensen && (r & 1) && r + 1 < q.R) {
      // The rest of the covariance is at most the product of the rest's deviations.
      const int rest = r + 1;
      const double n = static_cast<double>(q.R - rest) * A;
      const double sumA = q.pa.restSum[rest];
      const double sumB = pb.restSum[rest];
      const double restBound = std::sqrt(q.pa.restDeviation[rest] * pb.restDeviation[rest]) +
                               meanA * sumB + meanB * sumA - n * meanA * meanB;
      const double bound = (static_cast<double>(q.N) * (static_cast<double>(sab) + restBound) -
                            static_cast<double>(q.pa.sum) * static_cast<double>(sb)) /
                           den;
      if (bound < thr - kBoundSlack) return false;
    }
  }
  const std::int64_t num = q.N * sab - q.pa.sum * sb;
  score = static_cast<double>(num) / den;
  return true;
}

struct Candidate {
  double bound;
  int si, t;
};

// Buffers reused from one window pair to the next.
struct CompareScratch {
  std::vector<Candidate> candidates;
  std::vector<float> profileCross;  // angle profiles' correlation for every angle shift
};

WindowScore comparePlaced(const Pair& q, double threshold, const NccAccelerations& acc,
                          CompareScratch& scratch) {
  std::vector<Candidate>& candidates = scratch.candidates;
  WindowScore best;
  int bestIndex = -1;
  if (q.pa.variance <= 0) return best;
  const int shifts = 2 * q.S + 1;
  auto consider = [&](int si, int t) {
    const double thr = bestIndex < 0 ? threshold : std::max(threshold, best.score);
    double score = 0;
    const bool scored = q.A == kDefaultAngles ? fullScore<kDefaultAngles>(q, si, t, thr, acc, score)
                                              : fullScore<0>(q, si, t, thr, acc, score);
    if (!scored) return;
    if (score < threshold) return;
    const int index = si * q.A + t;
    if (bestIndex < 0 || score > best.score || (score == best.score && index < bestIndex)) {
      best = {score, si - q.S, t};
      bestIndex = index;
    }
  };
  if (!acc.projections) {
    for (int si = 0; si < shifts; ++si)
      for (int t = 0; t < q.A; ++t) consider(si, t);
    return best;
  }
  // Exact upper bounds from the projections. A window minus its mean splits into orthogonal
  // parts: ring effects (radius profile), column effects (angle profile) and the interaction.
  // For every shift, sum a'b' = <ring effects> + <column effects shifted by t> + <interactions>,
  // and the last term is at most |interaction_a| |interaction_b| (Cauchy-Schwarz).
  const double N = static_cast<double>(q.N);
  const double sa = static_cast<double>(q.pa.sum);
  candidates.clear();
  std::vector<float>& profileCross = scratch.profileCross;
  profileCross.resize(q.A);
  for (int si = 0; si < shifts; ++si) {
    const Placement& pb = q.pb[si];
    if (pb.variance <= 0) continue;
    const double den = std::sqrt(q.pa.variance * pb.variance);
    const double meanTerm = sa * static_cast<double>(pb.sum) / N;
    // Exact in any order: integer terms whose sum stays far below 2^53.
    double ringCross = dotDouble(q.pa.ringSums.data(), pb.ringSums.data(), q.R);
    ringCross = ringCross / q.A - meanTerm;
    const double interaction = std::sqrt(q.pa.interaction * pb.interaction);
    // Bound over every angle shift at once from the angle profiles' amplitude spectra: their
    // cyclic correlation minus its mean term is at most (1/A) sum_k |X_k| |Y_k|.
    const double spectral =
        dotDouble(q.pa.spectrum.data(), pb.spectrum.data(), static_cast<int>(pb.spectrum.size()));
    const double spectralBound = N * (ringCross + spectral / (q.A * q.R) + interaction) / den;
    if (spectralBound < threshold - kBoundSlack) continue;
    // Tighter, per ring: each ring's cyclic correlation minus its mean term is at most
    // (1/A) sum_k |X_rk| |Y_rk|, whatever the shift.
    {
      const int K = q.A / 2;
      const float* sa0 = q.a.ringSpectrum.data() + static_cast<std::size_t>(q.pa.first) * K;
      const float* sb0 = q.b.ringSpectrum.data() + static_cast<std::size_t>(pb.first) * K;
      const float dot = dotFloat(sa0, sb0, q.R * K);
      // float rounding is covered by a relative pad: the value only feeds an upper bound
      const double ringSpectral = static_cast<double>(dot) * (1 + 1e-4) + 1.0;
      if (N * (ringCross + ringSpectral / q.A) / den < threshold - kBoundSlack) continue;
    }
    // Float correlations, all shifts in lanes; each rounds by less than A * 2^-24 * |X| |Y|.
    const double crossPad = 4.0 * q.A * 6e-8 * q.pa.columnNorm * pb.columnNorm + 1.0;
    correlateProfiles(q.pa.columnSums.data(), pb.columnSums.data(), q.A, profileCross.data());
    // The bound below reaches the threshold only from this correlation on; the few shifts that
    // get there have their bound computed in full.
    const double crossCutoff =
        ((threshold - kBoundSlack) * den / N - ringCross + meanTerm - interaction) * q.R - crossPad;
    for (int t = 0; t < q.A; ++t) {
      if (static_cast<double>(profileCross[t]) < crossCutoff) continue;
      const double cross = static_cast<double>(profileCross[t]) + crossPad;
      const double bound = N * (ringCross + cross / q.R - meanTerm + interaction) / den;
      if (bound >= threshold - kBoundSlack) candidates.push_back({bound, si, t});
    }
  }
  std::sort(candidates.begin(), candidates.end(), [](const Candidate& x, const Candidate& y) {
    return x.bound > y.bound || (x.bound == y.bound && (x.si * 1000 + x.t) < (y.si * 1000 + y.t));
  });
  for (const Candidate& c : candidates) {
    const double thr = bestIndex < 0 ? threshold : std::max(threshold, best.score);
    if (c.bound < thr - kBoundSlack) break;
    consider(c.si, c.t);
  }
  return best;
}

// An image window claimed by several reference windows keeps the best-scoring one (the first
// among equals).
std::vector<WindowMatch> oneToOne(const std::vector<WindowMatch>& perRef) {
  int images = 0;
  for (const WindowMatch& m : perRef) images = std::max(images, m.image + 1);
  std::vector<int> owner(static_cast<std::size_t>(images), -1);
  for (std::size_t k = 0; k < perRef.size(); ++k) {
    int& o = owner[perRef[k].image];
    if (o < 0 || perRef[k].best.score > perRef[o].best.score) o = static_cast<int>(k);
  }
  std::vector<WindowMatch> out;
  for (std::size_t k = 0; k < perRef.size(); ++k)
    if (owner[perRef[k].image] == static_cast<int>(k)) out.push_back(perRef[k]);
  return out;
}

}  // namespace

WindowScore compareWindows(const LogPolarWindow& ref, const LogPolarWindow& image, int ringShifts,
                           double threshold, const NccAccelerations& acc) {
  if (!ref.valid || !image.valid || ref.angles != image.angles || ref.rows != image.rows) return {};
  const int R = ref.rows - 2 * ringShifts;
  if (R <= 0) return {};
  const Placement pa = place(ref, ringShifts, R);
  const std::vector<Placement> pb = placements(image, R, ringShifts);
  const Pair q{ref,        image, pa,         pb,
               ringShifts, R,     ref.angles, static_cast<std::int64_t>(R) * ref.angles};
  CompareScratch scratch;
  return comparePlaced(q, threshold, acc, scratch);
}

std::vector<WindowMatch> matchWindows(const std::vector<LogPolarWindow>& ref,
                                      const std::vector<LogPolarWindow>& image, int ringShifts,
                                      const NccMatchParams& params) {
  std::vector<WindowMatch> perRef;
  if (ref.empty() || image.empty()) return perRef;
  const int rows = ref.front().rows;
  const int A = ref.front().angles;
  const int R = rows - 2 * ringShifts;
  if (R <= 0) return perRef;
  std::vector<std::vector<Placement>> imagePlacements(image.size());
  for (std::size_t j = 0; j < image.size(); ++j)
    if (image[j].valid) imagePlacements[j] = placements(image[j], R, ringShifts);
  CompareScratch scratch;
  const NccAccelerations& acc = params.accelerations;
  const bool pruneAcrossWindows = acc.projections || acc.jensen;
  const auto kept = static_cast<std::size_t>(std::max(1, params.candidates));
  std::vector<WindowMatch> best;  // of the current reference window: the best `kept`, best first
  for (std::size_t i = 0; i < ref.size(); ++i) {
    if (!ref[i].valid) continue;
    const Placement pa = place(ref[i], ringShifts, R);
    best.clear();
    for (std::size_t j = 0; j < image.size(); ++j) {
      if (!image[j].valid || image[j].rows != rows || image[j].angles != A) continue;
      const Pair q{ref[i],     image[j], pa, imagePlacements[j],
                   ringShifts, R,        A,  static_cast<std::int64_t>(R) * A};
      // Once `kept` matches are known, only a better one matters: the worst of them becomes the
      // threshold (ties keep the earlier image window, as the plain loop does).
      const double thr =
          (pruneAcrossWindows && best.size() == kept) ? best.back().best.score : params.minScore;
      const WindowScore s = comparePlaced(q, thr, acc, scratch);
      if (s.score < params.minScore) continue;
      if (best.size() == kept && s.score <= best.back().best.score) continue;
      WindowMatch m;
      m.ref = static_cast<int>(i);
      m.image = static_cast<int>(j);
      m.best = s;
      auto at = std::find_if(best.begin(), best.end(),
                             [&](const WindowMatch& b) { return s.score > b.best.score; });
      best.insert(at, m);
      if (best.size() > kept) best.pop_back();
    }
    perRef.insert(perRef.end(), best.begin(), best.end());
  }
  return kept > 1 ? perRef : oneToOne(perRef);
}

std::vector<WindowMatch> bestOfEach(const std::vector<WindowMatch>& candidates) {
  // Each reference window's candidates come together, best first, and the first of them is what
  // a single candidate would have been: the best score, the earliest image window among equals
  // (comparePlaced's result does not depend on the threshold it was asked to beat, only whether
  // it is returned at all).
  std::vector<WindowMatch> best;
  for (const WindowMatch& m : candidates)
    if (best.empty() || best.back().ref != m.ref) best.push_back(m);
  return oneToOne(best);
}

}  // namespace facet
