#include "algorithms/edges/edge_profile_fit.hpp"

#include "algorithms/edges/edge_profile_tables.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <limits>
#include <memory>
#include <mutex>
#include <numbers>
#include <type_traits>
#include <vector>

#include <opencv2/core/hal/intrin.hpp>

#include "algorithms/geometry/spd_solve.hpp"

namespace facet {
namespace {

using edge_profile::apertureProfiles;
using edge_profile::ApertureProfiles;
using edge_profile::apertureView;
using edge_profile::erfView;
using edge_profile::ProfileInterval;
using edge_profile::ProfileView;

constexpr int kCapacity = 512;

// Four float lanes (GCC/Clang vector extension; SSE on x86, NEON on ARM).
using Lanes = float __attribute__((vector_size(16)));
using IntLanes = int __attribute__((vector_size(16)));

struct Samples {
  int count = 0;   // padded to a multiple of 4 with zero samples (weight 0 in the fit)
  int filled = 0;  // the samples before the padding (weight 1)
  // across, along, grey value minus the samples' mean (the fit's level is relative to it)
  alignas(16) std::array<float, kCapacity> s, t, v;
  // Per lane, the sum of v over the blocks of four in order: the first right-hand side of every
  // step's normal equations, the same for all of them.
  Lanes valueSums{};
};

float horizontalSum(Lanes x) {
  return (x[0] + x[1]) + (x[2] + x[3]);
}

// The integer range of dx for which lo <= dx * k + c <= hi on each row dy of a window, with
// c = dy * slope and invK = 1 / k (all dx when k ~ 0 and c fits). What does not depend on the row
// is settled once per window: the order of the two ends follows the sign of invK alone (lo < hi),
// so the end that bounds the first dx (lo, or hi when invK < 0) is chosen once.
struct RowRange {
  double slope, lo, hi, invK, firstEnd, lastEnd;
  bool flat;
  RowRange(double k, double inverse, double rowSlope, double low, double high)
      : slope(rowSlope),
        lo(low),
        hi(high),
        invK(inverse),
        firstEnd(inverse < 0 ? high : low),
        lastEnd(inverse < 0 ? low : high),
        flat(std::abs(k) < 1e-12) {}

  void restrict(int dy, int& first, int& last) const {
    const double c = dy * slope;
    if (flat) {
      if (c < lo || c > hi) last = first - 1;
      return;
    }
    first = std::max(first, static_cast<int>(std::ceil((firstEnd - c) * invK - 1e-9)));
    last = std::min(last, static_cast<int>(std::floor((lastEnd - c) * invK + 1e-9)));
  }
};

// Four consecutive pixels of a row as floats (OpenCV's widening loads; a conversion of a 4-byte
// vector extension type is done lane by lane). The pixels are copied to an aligned block first:
// the widening load reads them as one int (or int64), which a row's arbitrary address may not be
// aligned for; the copy is a single move.
Lanes fourPixels(const uchar* p) {
  alignas(16) uchar block[16] = {};
  std::memcpy(block, p, 4);
  Lanes out;
  cv::v_store(reinterpret_cast<float*>(&out),
              cv::v_cvt_f32(cv::v_reinterpret_as_s32(cv::v_load_expand_q(block))));
  return out;
}
Lanes fourPixels(const ushort* p) {
  alignas(16) ushort block[8] = {};
  std::memcpy(block, p, 4 * sizeof(ushort));
  Lanes out;
  cv::v_store(reinterpret_cast<float*>(&out),
              cv::v_cvt_f32(cv::v_reinterpret_as_s32(cv::v_load_expand(block))));
  return out;
}

// The sum of the grey values, as the samples were gathered one by one. 8-bit values are
// integers and every partial sum stays below 2^24, so it is exact in any order and four lanes
// give the same sum; 16-bit values (multiples of 1/256) round, so they keep the order.
template <typename T>
float sumOfValues(const float* v, int n) {
  float sum = 0;
  int i = 0;
  if constexpr (std::is_same_v<T, uchar>) {
    static_assert(kCapacity * 255 < (1 << 24));
    Lanes lanes{};
    for (; i + 4 <= n; i += 4) {
      Lanes four;
      std::memcpy(&four, v + i, sizeof four);
      lanes += four;
    }
    sum = horizontalSum(lanes);
  }
  for (; i < n; ++i) sum += v[i];
  return sum;
}

template <typename T>
void gather(const cv::Mat& image, cv::Point c, cv::Point2d n, double offset,
            const EdgeProfileParams& params, float scale, Samples& out) {
  const int reach = edgeProfileReach(params);
  int count = 0;
  const auto nx = static_cast<float>(n.x), ny = static_cast<float>(n.y);
  const double invX = std::abs(n.x) < 1e-12 ? 0.0 : 1.0 / n.x;
  const double invY = std::abs(n.y) < 1e-12 ? 0.0 : -1.0 / n.y;
  // s = dx nx + dy ny within offset +- halfAcross; t = -dx ny + dy nx within +- halfAlong.
  const RowRange across(n.x, invX, n.y, offset - params.halfAcross, offset + params.halfAcross);
  const RowRange along(-n.y, invY, n.x, -params.halfAlong, params.halfAlong);
  float* const s = out.s.data();
  float* const t = out.t.data();
  float* const v = out.v.data();
  // dx + 0..3 for four samples of a row (small integers: exact in float).
  const Lanes ramp{0, 1, 2, 3};
  // Near the image's border the window keeps the pixels inside it: a straight edge's fit needs
  // no symmetric window, only pixels on both sides of the edge (checked by the caller).
  int rowFrom = std::max(-reach, -c.y), rowTo = std::min(reach, image.rows - 1 - c.y);
  // Only the rows the window crosses hold samples: with (dx, dy) = (s n + t (-ny, nx)) / |n|^2,
  // s in [lo, hi] and |t| <= halfAlong span dy in [min(lo ny, hi ny), max(lo ny, hi ny)]
  // -+ |nx| halfAlong, over |n|^2. The others would find their column ranges empty (the margin
  // is far above the ranges' tolerance of 1e-9 px and the rounding).
  {
    const double lowY = (offset - params.halfAcross) * n.y,
                 highY = (offset + params.halfAcross) * n.y;
    const double alongY = std::abs(n.x) * params.halfAlong, norm2 = n.x * n.x + n.y * n.y;
    const double spanFrom = (std::min(lowY, highY) - alongY) / norm2;
    const double spanTo = (std::max(lowY, highY) + alongY) / norm2;
    // Compared as doubles: a degenerate normal's NaN or infinite span keeps the reach.
    rowFrom = static_cast<int>(std::max<double>(rowFrom, std::ceil(spanFrom - 1e-6)));
    rowTo = static_cast<int>(std::min<double>(rowTo, std::floor(spanTo + 1e-6)));
  }
  const int columnFrom = std::max(-reach, -c.x), columnTo = std::min(reach, image.cols - 1 - c.x);
  for (int dy = rowFrom; dy <= rowTo; ++dy) {
    int first = columnFrom, last = columnTo;
    across.restrict(dy, first, last);
    along.restrict(dy, first, last);
    last = std::min(last, first + (kCapacity - 4 - count) - 1);
    const T* row = image.ptr<T>(c.y + dy) + c.x;
    const float sRow = static_cast<float>(dy) * ny, tRow = static_cast<float>(dy) * nx;
    // Four samples at a time, the same operations on each as one at a time below. A row's last
    // four may reach past `last` while their pixels are still in the image: the samples beyond
    // it are written past `count`, where the next row or the padding overwrites them.
    int dx = first;
    for (; dx <= last && dx + 3 <= columnTo; dx += 4) {
      const Lanes fx = static_cast<float>(dx) + ramp;
      const Lanes across4 = fx * nx + sRow, along4 = tRow - fx * ny;
      const Lanes value4 = fourPixels(row + dx) * scale;
      std::memcpy(s + count, &across4, sizeof across4);
      std::memcpy(t + count, &along4, sizeof along4);
      std::memcpy(v + count, &value4, sizeof value4);
      count += std::min(4, last - dx + 1);
    }
    for (; dx <= last; ++dx, ++count) {
      const auto fx = static_cast<float>(dx);
      s[count] = fx * nx + sRow;
      t[count] = tRow - fx * ny;
      v[count] = static_cast<float>(row[dx]) * scale;
    }
  }
  const int real = out.filled = count;
  const float mean = real ? sumOfValues<T>(v, real) / static_cast<float>(real) : 0.0f;
  for (int i = 0; i < real; ++i) v[i] -= mean;
  while (count % 4) {
    const int i = count++;
    s[i] = t[i] = v[i] = 0.0f;
  }
  out.count = count;
  Lanes valueSums{};
  for (int i = 0; i < count; i += 4) {
    Lanes four;
    std::memcpy(&four, v + i, sizeof four);
    valueSums += four;
  }
  out.valueSums = valueSums;
}

// The table intervals of four lanes, one field per vector: each interval is one 16-byte load,
// and a 4x4 transpose sorts them into fields (fewer instructions than sixteen single loads).
struct Table {
  Lanes cdf, cdfSlope, pdf, pdfSlope;
};

Table tableLanes(const ProfileInterval* packed, IntLanes idx) {
  static_assert(sizeof(ProfileInterval) == sizeof(Lanes));
  // Byte offsets, scaled in one vector shift; as unsigned (idx >= 0) they need no sign extension
  // when moved out of the vector.
  const IntLanes offset = idx * static_cast<int>(sizeof(ProfileInterval));
  const auto* base = reinterpret_cast<const char*>(packed);
  Lanes q[4];
  for (int k = 0; k < 4; ++k)
    std::memcpy(&q[k], base + static_cast<unsigned>(offset[k]), sizeof(Lanes));
  const Lanes low01 = __builtin_shufflevector(q[0], q[1], 0, 4, 1, 5);
  const Lanes low23 = __builtin_shufflevector(q[2], q[3], 0, 4, 1, 5);
  const Lanes high01 = __builtin_shufflevector(q[0], q[1], 2, 6, 3, 7);
  const Lanes high23 = __builtin_shufflevector(q[2], q[3], 2, 6, 3, 7);
  return {__builtin_shufflevector(low01, low23, 0, 1, 4, 5),
          __builtin_shufflevector(low01, low23, 2, 3, 6, 7),
          __builtin_shufflevector(high01, high23, 0, 1, 4, 5),
          __builtin_shufflevector(high01, high23, 2, 3, 6, 7)};
}

// One Gauss-Newton step of the model v = a + b Phi(z), z = (s + phi t - e) / w, for (a, b, e)
// and, as the extra fourth unknown, either the width w (Extra::Width) or the turn phi of the
// normal (Extra::Turn); Extra::None fits (a, b, e) along the given normal (phi = 0, as it is
// before the turn is fitted). Returns false when the system is singular or the contrast not
// positive.
enum class Extra { None, Width, Turn };

template <Extra X>
bool step(const Samples& smp, const ProfileView& profile, double& a, double& b, double& e,
          double& w, double& phi) {
  constexpr int N = X == Extra::None ? 3 : 4;
  const ProfileInterval* packed = profile.data;
  const Lanes vScale = Lanes{} + profile.coordScale, vE = Lanes{} + static_cast<float>(e),
              vPhi = Lanes{} + static_cast<float>(phi);
  const Lanes vLow = Lanes{}, vHigh = Lanes{} + (static_cast<float>(profile.size) - 1.001f);
  Lanes acc[N][N + 1] = {};
  // Four samples; their weights are all 1 before the padding, which spares the products with
  // them there (a product with 1 is exact: the sums are the same).
  const auto accumulate = [&](int i, auto padded) {
    Lanes ss, tt, vv, ww = Lanes{} + 1.0f;
    std::memcpy(&ss, &smp.s[i], sizeof ss);
    std::memcpy(&tt, &smp.t[i], sizeof tt);
    std::memcpy(&vv, &smp.v[i], sizeof vv);
    if constexpr (decltype(padded)::value) {
      const IntLanes index = IntLanes{0, 1, 2, 3} + i;
      ww = index < smp.filled ? ww : Lanes{};
    }
    // None steps run before any turn is fitted (phi = 0, and s + 0 t = s, the same z): they
    // spare the turn's product.
    const Lanes z = X == Extra::None ? (ss - vE) * vScale : (ss + vPhi * tt - vE) * vScale;
    Lanes f = (z + profile.range) * profile.perUnit;
    f = f < vLow ? vLow : f;
    f = f > vHigh ? vHigh : f;
    const IntLanes idx = __builtin_convertvector(f, IntLanes);
    const Lanes r = f - __builtin_convertvector(idx, Lanes);
    const Table table = tableLanes(packed, idx);
    const Lanes cdf = table.cdf + r * table.cdfSlope;
    const Lanes pdf = (table.pdf + r * table.pdfSlope) * ww;
    Lanes basis[4] = {ww, cdf * ww, pdf, Lanes{}};
    if constexpr (X == Extra::Width) basis[3] = z * pdf;
    if constexpr (X == Extra::Turn) basis[3] = tt * pdf;
    // Row 0 (weight times weight, and times v) is the same in every step: the count of the
    // samples and smp.valueSums, which gather summed in the same order.
    for (int row = 1; row < N; ++row) {
      acc[row][N] += basis[row] * vv;
      for (int k = 0; k <= row; ++k) acc[row][k] += basis[row] * basis[k];
    }
  };
  int i = 0;
  for (; i + 4 <= smp.filled; i += 4) accumulate(i, std::false_type{});
  for (; i < smp.count; i += 4) accumulate(i, std::true_type{});
  std::array<std::array<double, N>, N> m{};
  std::array<double, N> y{};
  m[0][0] = smp.filled;  // each lane's count is exact, and so is their sum
  y[0] = horizontalSum(smp.valueSums);
  for (int r = 1; r < N; ++r) {
    y[r] = horizontalSum(acc[r][N]);
    for (int k = 0; k <= r; ++k) m[r][k] = horizontalSum(acc[r][k]);
  }
  if (!solveSpd<N>(m, y)) return false;
  a = y[0];
  b = y[1];
  if (b <= 1e-6) return false;
  // With D the tabulated derivative and k = derivScale (w for the erf, 1 for pixel units):
  // d/de = -b D / k, d/dw = -b z D / w (erf only), d/dphi = b t D / k.
  const double k = profile.derivScale;
  e += std::clamp(-y[2] * k / b, -0.5, 0.5);
  if constexpr (X == Extra::Width) w = std::clamp(w - y[3] * w / b, 0.3, 5.0);
  if constexpr (X == Extra::Turn) phi += std::clamp(y[3] * k / b, -0.2, 0.2);
  return true;
}

// Residual sum of squares after two (a, b, e) steps of the fixed-profile model.
double fitResidual(const Samples& smp, const ProfileView& view, double offset) {
  double a = 0, b = 0, e = offset, w = 1, phi = 0;
  if (!step<Extra::None>(smp, view, a, b, e, w, phi) ||
      !step<Extra::None>(smp, view, a, b, e, w, phi))
    return std::numeric_limits<double>::infinity();
  double rss = 0;
  for (int i = 0; i < smp.filled; ++i) {
    const double f = std::clamp((static_cast<double>(smp.s[i]) - e) * view.coordScale + view.range,
                                0.0, static_cast<double>(view.size - 1) / view.perUnit) *
                     view.perUnit;
    const int k = std::min(static_cast<int>(f), view.size - 1);
    const double r = smp.v[i] - a - b * (view.data[k].cdf + (f - k) * view.data[k].cdfSlope);
    rss += r * r;
  }
  return rss;
}

template <typename T>
void gatherAny(const cv::Mat& image, const EdgeSeed& seed, const EdgeProfileParams& params,
               Samples& out) {
  gather<T>(image, seed.pixel, seed.normal, seed.offset, params,
            std::is_same_v<T, ushort> ? 1.0f / 256 : 1.0f, out);
}

// Half the stretch along each seed that the blur search reads (pixels).
constexpr double kBlurHalfAlong = 2.0;

// The blur search reads each seed's profile at the nearest multiple of this many degrees, not
// the nearest degree. Why: it fits up to 18 sigmas, each of whose rows cost about as much to
// build as a search's whole profile fit, and the first image of a process paid for all of them
// (10 M instructions on a 640x480 bracket scene). The sigma hardly depends on it: the pixel
// square projected on a normal at any angle has the same variance (1/12), so a profile read
// 2.5 degrees off has the right width and differs only in its tails' shape.
constexpr int kBlurSearchDegrees = 5;

// The blur model and sigma whose exact profiles fit the seeds best (least residual sum of
// squares), searched around the erf width's sigma in steps of 0.02 px. Why both models: a lens
// blurs before the pixel integrates (a continuous Gaussian times the pixel square), a blur filter
// run on a sampled image after it (a discrete kernel); at sigma 0.5-0.8 the two profiles differ by
// up to 3% of the contrast, and fitting the wrong one moves axis-aligned edges by up to 0.03 px
// with their subpixel phase. Also why not the erf width alone: it is the width of the wrong
// shape, biased by the edges' subpixel phases by up to +-0.05 px (estimateEdgeBlur).
EdgeBlur fitBlurModel(const cv::Mat& image, const std::vector<const EdgeSeed*>& seeds,
                      const EdgeProfileParams& params, double width,
                      std::optional<bool> onlyModel) {
  // The profiles are those of a straight edge: a short stretch along each seed keeps an arc's
  // sagitta out of the profile's width (a disc of radius 15 px read over +-6 px gave sigma 1.10
  // for 1.00; over +-2 px the sagitta is 0.13 px, and the test of that disc reads 1.00 +- 0.1).
  EdgeProfileParams stretch = params;
  stretch.halfAlong = std::min(params.halfAlong, kBlurHalfAlong);
  // Default-initialised (gather writes every sample it counts): 8 KB each need no zeroing.
  const std::unique_ptr<Samples[]> samples(new Samples[seeds.size()]);
  for (size_t i = 0; i < seeds.size(); ++i) {
    if (image.depth() == CV_16U)
      gatherAny<ushort>(image, *seeds[i], stretch, samples[i]);
    else
      gatherAny<uchar>(image, *seeds[i], stretch, samples[i]);
  }
  const double sigma0 = std::round(std::sqrt(std::max(width * width - 1.0 / 12, 0.04)) * 50) / 50;
  // The seeds that a straight blurred step fits worst at the erf width's sigma (a corner, a tight
  // arc, a neighbouring edge in the window) would take their misfit for blur; the worst quarter
  // is left out of the search.
  std::vector<size_t> kept(seeds.size());
  for (size_t i = 0; i < seeds.size(); ++i) kept[i] = i;
  // Per model, each seed's residual at sigma0: the misfit ranking below and the search's step 0.
  std::array<std::vector<double>, 2> atSigma0;
  if (seeds.size() >= 8) {
    std::vector<double> misfit(seeds.size(), std::numeric_limits<double>::infinity());
    for (const bool grid : {false, true}) {
      if (onlyModel && *onlyModel != grid) continue;
      const auto profiles = apertureProfiles(sigma0, grid);
      std::vector<double>& residual = atSigma0[grid];
      residual.resize(seeds.size());
      for (size_t i = 0; i < seeds.size(); ++i) {
        residual[i] =
            fitResidual(samples[i], apertureView(*profiles, seeds[i]->normal, kBlurSearchDegrees),
                        seeds[i]->offset);
        misfit[i] = std::min(misfit[i], residual[i]);
      }
    }
    std::sort(kept.begin(), kept.end(), [&](size_t a, size_t b) { return misfit[a] < misfit[b]; });
    kept.resize(seeds.size() - seeds.size() / 4);
  }
  const auto rssAt = [&](int step, bool grid) {
    double rss = 0;
    if (step == 0 && !atSigma0[grid].empty()) {
      for (const size_t i : kept) rss += atSigma0[grid][i];
      return rss;
    }
    const auto profiles = apertureProfiles(sigma0 + 0.02 * step, grid);
    for (const size_t i : kept)
      rss += fitResidual(samples[i], apertureView(*profiles, seeds[i]->normal, kBlurSearchDegrees),
                         seeds[i]->offset);
    return rss;
  };
  // Per model: the best of every third step of +-6, then the best of the steps next to it. The
  // residual is smooth and single-welled in sigma, so each pass walks downhill from its start
  // and stops where the residual rises: the steps it leaves out cannot be lower. (Each sigma's
  // profile rows are built on first use, and on a process's first image they cost more than the
  // fits; visiting all 9 steps of each model built twice as many.)
  double best = std::numeric_limits<double>::infinity(), bestSigma = sigma0;
  bool bestGrid = false;
  for (const bool grid : {false, true}) {
    if (onlyModel && *onlyModel != grid) continue;
    double modelBest = std::numeric_limits<double>::infinity();
    int bestStep = 0;
    const auto tryStep = [&](int step) {
      if (sigma0 + 0.02 * step < 0.2) return false;
      const double rss = rssAt(step, grid);
      if (rss >= modelBest) return false;
      modelBest = rss, bestStep = step;
      return true;
    };
    // From `from`, steps of `stride` up to `reach` away, first one way then, if that did not
    // descend at once, the other.
    const auto descend = [&](int from, int stride, int reach) {
      for (const int direction : {1, -1}) {
        bool moved = false;
        for (int k = stride; k <= reach && tryStep(from + direction * k); k += stride) moved = true;
        if (moved) return;
      }
    };
    tryStep(0);
    descend(0, 3, 6);
    descend(bestStep, 1, 2);
    if (modelBest < best) best = modelBest, bestSigma = sigma0 + 0.02 * bestStep, bestGrid = grid;
  }
  return {std::sqrt(bestSigma * bestSigma + 1.0 / 12), bestGrid};
}

}  // namespace

double profileHalfAlong(double curvature, const EdgeProfileParams& params) {
  const double k = std::abs(curvature);
  if (k * params.halfAlong * params.halfAlong <= 6 * params.maxCurvatureBias)
    return params.halfAlong;
  return std::clamp(std::sqrt(6 * params.maxCurvatureBias / k), params.minAlong, params.halfAlong);
}

double profileWindowBias(const EdgeProfileParams& params) {
  return params.halfAlong * params.halfAlong / 6;
}

int edgeProfileReach(const EdgeProfileParams& params) {
  return static_cast<int>(
      std::ceil(std::sqrt((params.halfAcross + 1.5) * (params.halfAcross + 1.5) +
                          params.halfAlong * params.halfAlong)));
}

std::optional<EdgePoint> fitEdgeProfile(const cv::Mat& image, cv::Point pixel, cv::Point2d normal,
                                        double offset, const EdgeProfileParams& params,
                                        double* fittedWidth) {
  thread_local Samples smp;
  if (image.depth() == CV_16U)
    gather<ushort>(image, pixel, normal, offset, params, 1.0f / 256, smp);
  else
    gather<uchar>(image, pixel, normal, offset, params, 1.0f, smp);
  if (smp.count < 12) return std::nullopt;

  // With a known width: (a, b, e) steps, the last one also turning the normal. Otherwise the
  // steps fit the width, and a final step the turn.
  const bool fitWidth = params.width <= 0;
  // A known width w is the erf width of the blur and the pixel aperture together; the aperture's
  // variance along any normal is (cos^2 + sin^2) / 12 = 1/12, the rest is the PSF.
  std::shared_ptr<ApertureProfiles> aperture;
  ProfileView view;  // the known width's profile at the normal's angle (fixed during the fit)
  if (!fitWidth) {
    aperture = apertureProfiles(std::sqrt(std::max(params.width * params.width - 1.0 / 12, 0.04)),
                                params.blurOnPixelGrid);
    view = apertureView(*aperture, normal);
  }
  double a = 0, b = 0, e = offset, w = fitWidth ? params.initialWidth : params.width, phi = 0;
  const int iterations = std::max(1, params.iterations);
  for (int it = 0; it < iterations; ++it) {
    const bool last = it == iterations - 1;
    bool ok = true;
    if (fitWidth) {
      ok = step<Extra::Width>(smp, erfView(w), a, b, e, w, phi) &&
           (!last || step<Extra::Turn>(smp, erfView(w), a, b, e, w, phi));
    } else {
      ok = last ? step<Extra::Turn>(smp, view, a, b, e, w, phi)
                : step<Extra::None>(smp, view, a, b, e, w, phi);
    }
    if (!ok) return std::nullopt;
  }
  // A seed normal off by more than a degree or two (noise, a corner nearby) needs more turn
  // steps: the linearisation in phi is only good for small turns. Give up when they do not
  // settle.
  if (!fitWidth && std::abs(phi) > 0.03) {
    double previous = phi;
    for (int extra = 0; extra < 3; ++extra) {
      if (!step<Extra::Turn>(smp, view, a, b, e, w, phi)) return std::nullopt;
      if (std::abs(phi - previous) < 0.003) break;
      previous = phi;
    }
    if (std::abs(phi - previous) >= 0.003) return std::nullopt;
  }
  if (std::abs(e - offset) > 1.0) return std::nullopt;  // wandered off: not a clean edge
  if (fittedWidth) *fittedWidth = w;

  // The fitted line is {p : (p - c) . (n + phi t) = e}; the foot of the pixel centre on it lies
  // e / |n + phi t| along the turned unit normal.
  const cv::Point2d t{-normal.y, normal.x};
  cv::Point2d n = normal + phi * t;
  n /= std::sqrt(n.x * n.x + n.y * n.y);
  return EdgePoint{cv::Point2d(pixel) + e / std::sqrt(1.0 + phi * phi) * n, n,
                   b / (w * std::sqrt(2 * std::numbers::pi))};
}

EdgeBlur estimateEdgeBlur(const cv::Mat& image, const std::vector<EdgeSeed>& seeds,
                          const EdgeProfileParams& params, int maxSamples,
                          std::optional<bool> onlyModel) {
  EdgeProfileParams fitParams = params;
  fitParams.width = 0;
  fitParams.iterations = std::max(params.iterations, 3);
  const int reach = edgeProfileReach(fitParams);
  std::vector<double> widths;
  std::vector<const EdgeSeed*> fitted, axis;  // axis: normal within 10 deg of an axis
  constexpr double kAxisSine = 0.1736;        // sin(10 deg)
  const size_t stride = std::max<size_t>(1, seeds.size() / std::max(1, maxSamples));
  for (size_t i = 0; i < seeds.size(); i += stride) {
    const EdgeSeed& s = seeds[i];
    if (s.pixel.x < reach || s.pixel.y < reach || s.pixel.x >= image.cols - reach ||
        s.pixel.y >= image.rows - reach)
      continue;
    double w = 0;
    if (!fitEdgeProfile(image, s.pixel, s.normal, s.offset, fitParams, &w)) continue;
    widths.push_back(w);
    fitted.push_back(&s);
    if (std::min(std::abs(s.normal.x), std::abs(s.normal.y)) < kAxisSine) axis.push_back(&s);
  }
  if (widths.empty()) return {params.initialWidth, params.blurOnPixelGrid};
  std::nth_element(widths.begin(), widths.begin() + widths.size() / 2, widths.end());
  const double width = widths[widths.size() / 2];
  // The median erf width only starts the search: an erf is not the shape of a profile that holds
  // the pixel aperture (or a discrete kernel), and its width is biased by the edges' subpixel
  // phases. At sigma 0.5 on the pixel grid that cost 0.035 px at 2-3 degrees (one phase for an
  // axis-aligned edge, a slowly drifting one near it) and 0.012 px at 44-46 degrees (where the
  // pixels sample the profile only every 0.7 px). The blur is the exact profiles' best sigma, from
  // the axis-near edges where they dominate (their phase bias is the largest).
  const bool axisDominated = axis.size() * 2 >= widths.size();
  std::vector<const EdgeSeed*>& chosen = axisDominated ? axis : fitted;
  constexpr size_t kModelSeeds = 16;
  if (chosen.size() > kModelSeeds) {
    std::vector<const EdgeSeed*> fewer;
    for (size_t i = 0; i < kModelSeeds; ++i)
      fewer.push_back(chosen[i * chosen.size() / kModelSeeds]);
    chosen.swap(fewer);
  }
  return fitBlurModel(image, chosen, params, width, onlyModel);
}

double estimateEdgeWidth(const cv::Mat& image, const std::vector<EdgeSeed>& seeds,
                         const EdgeProfileParams& params, int maxSamples) {
  return estimateEdgeBlur(image, seeds, params, maxSamples).width;
}

}  // namespace facet
