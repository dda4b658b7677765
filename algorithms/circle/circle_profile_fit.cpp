#include "algorithms/circle/circle_profile_fit.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <memory>
#include <numbers>
#include <optional>
#include <span>
#include <utility>

#include <Eigen/Dense>

#include "algorithms/circle/censored_pixels.hpp"
#include "algorithms/circle/diamond_angle.hpp"
#include "algorithms/circle/rim_band.hpp"
#include "algorithms/circle/step_profile.hpp"
#include "algorithms/circle/weighted_normal_equations.hpp"
#include "algorithms/edges/row_runs.hpp"
#include "algorithms/geometry/levenberg_marquardt.hpp"
#include "algorithms/image/sensor_limit.hpp"

namespace facet {
namespace {

constexpr double kPi = std::numbers::pi;
// Share of the band's pixels that contaminated sectors must hold before the fit is repeated
// without them (contaminatedBins).
constexpr double kMinRefitShare = 0.02;

using rim_band::contaminatedBins;
using rim_band::dropForeignGradients;
using rim_band::greyAt;
using rim_band::medianOf;
using rim_band::robustSigma;
using rim_band::Sample;
using step_profile::gaussian;
using step_profile::upperTail;

using Vector8 = Eigen::Matrix<double, 8, 1>;
using Matrix8 = Eigen::Matrix<double, 8, 8>;
using Columns = Eigen::Matrix<double, Eigen::Dynamic, 8>;

using diamond_angle::binOf;
using diamond_angle::rowBins;

// A stretch of a row of the band: columns [x0, x1).
struct Stretch {
  int row, x0, x1;
};

// Appends the columns of stretch s (on the row dy below the centre) within the narrow band,
// squared distance from the centre in [lo2, hi2], to `out`: at most two stretches, since along a
// row the squared distance falls up to the centre's column and rises after it. Their ends come
// from square roots and are then moved to where the per-pixel test itself changes.
void narrowStretches(const Stretch& s, double centreX, double dy, double lo2, double hi2,
                     std::vector<Stretch>& out) {
  const double dy2 = dy * dy;
  if (dy2 > hi2) return;  // no pixel of the row is near enough
  auto rho2 = [&](int x) {
    const double dx = static_cast<double>(x) - centreX;
    return dx * dx + dy2;
  };
  // The first column of [a, b) at which `test` holds (false, then true along the row), or b,
  // looked for from `guess`.
  auto first = [](int a, int b, double guess, auto test) {
    int x = static_cast<int>(
        std::clamp(std::ceil(guess), static_cast<double>(a), static_cast<double>(b)));
    while (x > a && test(x - 1)) --x;
    while (x < b && !test(x)) ++x;
    return x;
  };
  const double inner = lo2 > dy2 ? std::sqrt(lo2 - dy2) : 0.0, outer = std::sqrt(hi2 - dy2);
  // The first column right of the centre: to its left the squared distance falls.
  const int split = static_cast<int>(
      std::clamp(std::floor(centreX) + 1.0, static_cast<double>(s.x0), static_cast<double>(s.x1)));
  const int a = first(s.x0, split, centreX - outer, [&](int x) { return rho2(x) <= hi2; });
  const int b = first(a, split, centreX - inner, [&](int x) { return rho2(x) < lo2; });
  if (a < b) out.push_back({s.row, a, b});
  const int c = first(split, s.x1, centreX + inner, [&](int x) { return rho2(x) >= lo2; });
  const int d = first(c, s.x1, centreX + outer, [&](int x) { return rho2(x) > hi2; });
  if (c < d) out.push_back({s.row, c, d});
}

// One pass of the blurred-step model over the band at parameters q (cx, cy, R, s, level, ramp x,
// ramp y, contrast b; pixel coordinates x, y relative to the starting centre): the residuals
// grey - model and the Jacobian's columns that change (d/dcx, d/dcy, d/dR, d/ds, d/db). A
// function of its own so that the arrays can be declared distinct (__restrict): otherwise the
// compiler would check more pairs of them for overlap than it is willing to, and the loops would
// not vectorise.
FACET_PIXEL_PASS void evaluateProfile(const Vector8& q, std::ptrdiff_t n,
                                      const double* __restrict x, const double* __restrict y,
                                      const double* __restrict grey, double* __restrict out,
                                      double* __restrict cx, double* __restrict cy,
                                      double* __restrict cr, double* __restrict cs,
                                      double* __restrict cb) {
  const double cx0 = q(0), cy0 = q(1), radius = q(2), s = q(3), level = q(4), rampX = q(5),
               rampY = q(6), b = q(7);
  const double inv = 1.0 / s, bNorm = b * (1.0 / (std::sqrt(2.0 * kPi) * s));
  for (std::ptrdiff_t i = 0; i < n; ++i) {
    const double ex = x[i] - cx0, ey = y[i] - cy0;
    const double rho = std::max(std::sqrt(ex * ex + ey * ey), 1e-9);
    const double z = (rho - radius) * inv, gauss = gaussian(z);
    const double phi = upperTail(z, gauss);  // Phi(-d / s)
    const double bg = bNorm * gauss;         // b * pdf(d; s)
    const double bgPerRho = bg / rho;
    out[i] = grey[i] - (level + rampX * x[i] + rampY * y[i] + b * phi);
    // dI/dd = -b g; dd/dcx = -ex/rho, dd/dcy = -ey/rho, dd/dR = -1; dI/ds = b g d / s.
    cx[i] = ex * bgPerRho;
    cy[i] = ey * bgPerRho;
    cr[i] = bg;
    cs[i] = bg * z;
    cb[i] = phi;
  }
}

// The same pass with each pixel's area in the model (step_profile::pixelStep): q(3) is the lens's
// blur alone, and the pixel's box is averaged over along the rim's normal there. For sharp
// images only (see fitCircleProfile); a plain loop.
void evaluatePixelProfile(const Vector8& q, std::ptrdiff_t n, const double* x, const double* y,
                          const double* grey, double* out, double* cx, double* cy, double* cr,
                          double* cs, double* cb) {
  const double cx0 = q(0), cy0 = q(1), radius = q(2), s = q(3), level = q(4), rampX = q(5),
               rampY = q(6), b = q(7);
  for (std::ptrdiff_t i = 0; i < n; ++i) {
    const double ex = x[i] - cx0, ey = y[i] - cy0;
    const double rho = std::max(std::sqrt(ex * ex + ey * ey), 1e-9);
    const step_profile::PixelStep e = step_profile::pixelStep(rho - radius, s, ex / rho, ey / rho);
    out[i] = grey[i] - (level + rampX * x[i] + rampY * y[i] + b * e.value);
    // dI/dd = b e.dd; dd/dcx = -ex/rho, dd/dcy = -ey/rho, dd/dR = -1 (the normal's turn with the
    // centre is second order).
    cx[i] = -b * e.dd * ex / rho;
    cy[i] = -b * e.dd * ey / rho;
    cr[i] = -b * e.dd;
    cs[i] = b * e.ds;
    cb[i] = e.value;
  }
}

// Tukey's biweight of the n residuals r with tuning constant c. A pass of its own, so that it
// vectorises.
FACET_PIXEL_PASS void tukeyWeight(std::ptrdiff_t n, const double* __restrict r, double c,
                                  double* __restrict weight) {
  for (std::ptrdiff_t i = 0; i < n; ++i) {
    const double u = std::abs(r[i]) / c;
    weight[i] = u >= 1.0 ? 0.0 : (1 - u * u) * (1 - u * u);
  }
}

// The Jacobian's columns of the second harmonic's (a, c) at parameters q (fitRimShape, below),
// from the column of the radius `cr`.
FACET_PIXEL_PASS void secondHarmonicColumns(const Vector8& q, std::ptrdiff_t n,
                                            const double* __restrict x, const double* __restrict y,
                                            const double* __restrict cr, double* __restrict ha,
                                            double* __restrict hc) {
  const double cx0 = q(0), cy0 = q(1);
  for (std::ptrdiff_t i = 0; i < n; ++i) {
    const double ex = x[i] - cx0, ey = y[i] - cy0;
    const double perRho = -cr[i] / std::max(std::sqrt(ex * ex + ey * ey), 1e-9);
    ha[i] = perRho * (ex * ex - ey * ey);
    hc[i] = perRho * 2.0 * ex * ey;
  }
}

}  // namespace

std::optional<CircleProfileFit> fitCircleProfile(const cv::Mat& image, cv::Point2d centre,
                                                 double radius,
                                                 const std::vector<cv::Point2d>& rimPoints,
                                                 const std::vector<EdgePoint>& foreignPoints,
                                                 double noiseSigma, double maxShift,
                                                 const cv::Matx22d& toCircle, bool fitRimShape) {
  if (image.empty() || radius <= 1.0 || rimPoints.size() < 3) return std::nullopt;

  // Angular bins of about 2 px of arc: a bin takes part when an inlier edge point lies in it.
  const int bins = std::max(16, static_cast<int>(2.0 * kPi * radius / 2.0));
  std::vector<std::uint8_t> covered(bins, 0);
  for (const auto& q : rimPoints) covered[binOf(q.x - centre.x, q.y - centre.y, bins)] = 1;
  // A small rim (under kSmallRim px) has few bins to spare: it keeps a wider band and the ends of
  // its covered runs (below); a long rim trades a little information for less contamination.
  constexpr double kSmallRim = 25.0;
  const bool smallRim = radius < kSmallRim;
  // Gaps of up to 2 bins closed; on a long rim 1 bin (about 2 px of arc) dropped at each end of
  // every covered run. Pixels near detected foreign edges are excluded below and contaminated
  // sectors after the first fit, so on a small rim the margin only costs information (at
  // r = 10 px it cost 6% of the centre's precision on a 70% rim with clutter).
  covered = rim_band::closedCoverage(covered, smallRim ? 0 : 1);
  // Half-width of the band, pixels. Its pixels away from the edge pin down the levels and the
  // illumination ramp, which the radius (and, on a partial rim, the centre) is correlated with:
  // 6 px instead of 4 gains about 15% in the radius of faint rims and in the centre of a partly
  // occluded small rim, and 8 px on a small rim under a ramp another 6% in the centre and 10% in
  // the radius (on a long rim it takes in more clutter than it gains). A rim with pixels to spare
  // keeps only the inner kNarrowBand (below).
  const double halfBand = smallRim ? 8.0 : 6.0;
  constexpr double kNarrowBand = 4.0;

  // An elliptic rim: its offsets from the centre map to the circle's by toCircle (symmetric,
  // determinant 1), whose larger eigenvalue `stretch` is the square root of the axes' ratio. Its
  // band lies in the image annulus from (R - halfBand) / stretch to (R + halfBand) * stretch.
  const bool elliptic = toCircle != cv::Matx22d::eye();
  const double halfTrace = (toCircle(0, 0) + toCircle(1, 1)) / 2.0;
  const double stretch =
      elliptic
          ? halfTrace + std::sqrt(std::max(0.0, halfTrace * halfTrace - cv::determinant(toCircle)))
          : 1.0;
  // An offset's distance from the rim, in the circle's coordinates.
  auto mappedDistance = [&](double dx, double dy) {
    return cv::norm(toCircle * cv::Vec2d(dx, dy)) - radius;
  };

  // The band |rho - R| <= halfBand inside the image, as stretches of rows: a big rim's band holds
  // several times the pixels the fit keeps (the thinning below), and only those need their bins,
  // coordinates and grey values.
  const double rOut = (radius + halfBand) * stretch,
               rIn = std::max(0.0, (radius - halfBand) / stretch);
  const int x0 = std::max(0, static_cast<int>(std::floor(centre.x - rOut)));
  const int x1 = std::min(image.cols - 1, static_cast<int>(std::ceil(centre.x + rOut)));
  const int y0 = std::max(0, static_cast<int>(std::floor(centre.y - rOut)));
  const int y1 = std::min(image.rows - 1, static_cast<int>(std::ceil(centre.y + rOut)));
  // Pixels near a foreign edge (clutter, an occluder's border) stay out of the fit.
  const rim_band::ForeignReach tainted(foreignPoints, noiseSigma,
                                       cv::Rect(x0, y0, x1 - x0 + 1, y1 - y0 + 1));
  // The band's pixels that take part (in a covered bin, clear of foreign edges), in the runs'
  // order. Along a row the angular bin is monotonic (diamond_angle.hpp), so a run whose end pixels'
  // bins enclose covered bins only is covered throughout and needs no bin per pixel here; the
  // others are tested pixel by pixel.
  std::vector<int> uncoveredBelow(bins + 1, 0);  // bins below b that are not covered
  for (int b = 0; b < bins; ++b) uncoveredBelow[b + 1] = uncoveredBelow[b] + (covered[b] == 0);
  const RowRuns runs =
      annulusRowRuns(centre, rIn, rOut, cv::Rect(x0, y0, x1 - x0 + 1, y1 - y0 + 1));
  std::vector<Stretch> band;
  band.reserve(runs.size());
  std::vector<int> pixelBins;
  std::size_t inBand = 0;
  for (const RowRun& run : runs) {
    const int n = run.x1 - run.x0;
    if (n <= 0) continue;
    const double dy = run.y - centre.y;
    const std::uint8_t* taint = tainted.row(run.y);
    const int first = binOf(static_cast<double>(run.x0) - centre.x, dy, bins);
    const int last = binOf(static_cast<double>(run.x1 - 1) - centre.x, dy, bins);
    if (taint == nullptr &&
        uncoveredBelow[std::max(first, last) + 1] == uncoveredBelow[std::min(first, last)]) {
      band.push_back({run.y, run.x0, run.x1});
      inBand += static_cast<std::size_t>(n);
      continue;
    }
    pixelBins.resize(static_cast<std::size_t>((n + 3) & ~3));  // rowBins' groups
    rowBins(run.x0, n, centre.x, dy, bins, pixelBins.data());
    for (int i = 0; i < n; ++i) {
      const int x = run.x0 + i;
      if (!covered[pixelBins[i]] || (taint != nullptr && taint[x] != 0)) continue;
      if (!band.empty() && band.back().row == run.y && band.back().x1 == x)
        ++band.back().x1;
      else
        band.push_back({run.y, x, x + 1});
      ++inBand;
    }
  }
  if (inBand < 30) return std::nullopt;

  // Start: outside and inside levels from the band's two halves, blur 1.2 px, no ramp.
  // Every few pixels suffice for a starting level (a big rim's band has thousands).
  // Every pixel read is written to both lists and counted in the one its side picks: which side
  // a pixel lies on follows no pattern the branch predictor learns.
  const std::size_t levelStride = std::max<std::size_t>(1, inBand / 1024);
  const std::size_t levelRoom = inBand / levelStride + 1;
  const auto inside = std::make_unique_for_overwrite<double[]>(levelRoom);
  const auto outside = std::make_unique_for_overwrite<double[]>(levelRoom);
  std::size_t insideCount = 0, outsideCount = 0;
  {
    std::size_t next = 0, start = 0;  // band indices: the next pixel read, the stretch's first
    for (const Stretch& s : band) {
      const std::size_t end = start + static_cast<std::size_t>(s.x1 - s.x0);
      for (; next < end; next += levelStride) {
        const int column = s.x0 + static_cast<int>(next - start);
        const double dx = column - centre.x, dy = s.row - centre.y;
        const double d = elliptic ? mappedDistance(dx, dy) : std::sqrt(dx * dx + dy * dy) - radius;
        const double grey = greyAt(image, column, s.row);
        inside[insideCount] = grey;
        outside[outsideCount] = grey;
        insideCount += d < -2.0;
        outsideCount += d > 2.0;
      }
      start = end;
    }
  }
  if (insideCount == 0 || outsideCount == 0) return std::nullopt;
  Vector8 p;
  const CensoredPixels::Step start = CensoredPixels::startingStep(
      medianOf({outside.get(), outside.get() + outsideCount}),
      medianOf({inside.get(), inside.get() + insideCount}), sensorLimit(image.depth()));
  p << 0.0, 0.0, radius, 1.2, start.level, 0.0, 0.0, start.contrast;

  // A clean rim needs far fewer pixels than a big circle has: keep an evenly spread share of the
  // bins, as many pixels as rim_band::pixelsNeeded. When pixels are to spare, the narrower band
  // goes first: its pixels carry more about the rim.
  const double lo = std::max(0.0, radius - kNarrowBand), hi = radius + kNarrowBand;
  bool narrow = false;  // keep the pixels within kNarrowBand of the rim only
  double share = 1.0;   // ... and of their bins this share
  // The narrow band's pixels of the band (filled when narrow), in the band's order.
  std::vector<Stretch> narrowBand;
  std::size_t narrowPixels = 0;
  if (noiseSigma > 0.0 && !elliptic) {  // an elliptic rim's band is narrowed below
    const double snr = p(7) / noiseSigma;
    auto needed = [&](double halfWidth) { return rim_band::pixelsNeeded(snr, halfWidth); };
    if (static_cast<double>(inBand) > needed(halfBand)) {
      narrow = true;
      narrowBand.reserve(2 * band.size());
      for (const Stretch& s : band)
        narrowStretches(s, centre.x, s.row - centre.y, lo * lo, hi * hi, narrowBand);
      for (const Stretch& s : narrowBand) narrowPixels += static_cast<std::size_t>(s.x1 - s.x0);
      share = needed(kNarrowBand) / static_cast<double>(narrowPixels);
    }
  }
  std::vector<Sample> samples;
  // Which bins the share keeps, once per bin rather than per pixel.
  std::vector<std::uint8_t> keptBin(bins, 1);
  if (narrow && share < 1.0)
    for (int b = 0; b < bins; ++b)
      keptBin[b] = std::floor((b + 1) * share) != std::floor(b * share);
  // The pixels kept, in the band's order: all of the band's, or the narrow band's in kept bins,
  // picked without a branch per pixel (whether a bin is kept follows no pattern the branch
  // predictor learns).
  struct Pick {
    int column, row, bin;
  };
  const auto picks = std::make_unique_for_overwrite<Pick[]>(narrow ? narrowPixels : inBand);
  std::size_t picked = 0;
  for (const Stretch& s : narrow ? narrowBand : band) {
    const int n = s.x1 - s.x0;
    pixelBins.resize(static_cast<std::size_t>((n + 3) & ~3));  // rowBins' groups
    rowBins(s.x0, n, centre.x, s.row - centre.y, bins, pixelBins.data());
    for (int k = 0; k < n; ++k) {
      picks[picked] = {s.x0 + k, s.row, pixelBins[k]};
      picked += keptBin[pixelBins[k]];
    }
  }
  samples.reserve(picked);
  for (std::size_t k = 0; k < picked; ++k) {
    const Pick& e = picks[k];
    samples.push_back({e.column - centre.x, e.row - centre.y, greyAt(image, e.column, e.row), e.bin,
                       e.column, e.row});
  }
  if (elliptic) {
    // The band about the elliptic rim (the image annulus holds it with margins) and, as for a
    // circle, a big clean rim's narrower band in an evenly spread share of the bins: judged on
    // the offsets mapped once into the circle's coordinates.
    for (Sample& e : samples) {
      const cv::Vec2d mapped = toCircle * cv::Vec2d(e.x, e.y);
      e.x = mapped[0];
      e.y = mapped[1];
    }
    auto outside = [&](double limit) {
      return [&, limit](const Sample& e) {
        return std::abs(std::sqrt(e.x * e.x + e.y * e.y) - radius) > limit;
      };
    };
    std::erase_if(samples, outside(halfBand));
    const double snr = noiseSigma > 0.0 ? p(7) / noiseSigma : 0.0;
    if (noiseSigma > 0.0 &&
        static_cast<double>(samples.size()) > rim_band::pixelsNeeded(snr, halfBand)) {
      std::erase_if(samples, outside(kNarrowBand));
      share = rim_band::pixelsNeeded(snr, kNarrowBand) / static_cast<double>(samples.size());
      if (share < 1.0)
        std::erase_if(samples, [&](const Sample& e) {
          return std::floor((e.bin + 1) * share) == std::floor(e.bin * share);
        });
    }
    // The gradient screen judges a pixel by the rim's normal near it and its distance from the
    // rim: an offset along that normal (toCircle^T times the mapped offset; toCircle is
    // symmetric) as long as the mapped offset, the circle's radius plus that distance.
    for (Sample& e : samples) {
      const cv::Vec2d mapped(e.x, e.y);
      const cv::Vec2d along = cv::normalize(toCircle * mapped) * cv::norm(mapped);
      e.x = along[0];
      e.y = along[1];
    }
  }
  if (noiseSigma > 0.0) {
    // After the thinning, so that a big rim pays only for the pixels it keeps.
    dropForeignGradients(samples, image, radius, noiseSigma,
                         cv::Rect(x0, y0, x1 - x0 + 1, y1 - y0 + 1));
    if (samples.size() < 30) return std::nullopt;
  }
  if (elliptic) {  // the model's coordinates: the mapped offsets
    if (samples.size() < 30) return std::nullopt;
    for (Sample& e : samples) {
      const cv::Vec2d mapped = toCircle * cv::Vec2d(e.column - centre.x, e.row - centre.y);
      e.x = mapped[0];
      e.y = mapped[1];
    }
  }
  // Tukey's constant, in robust sigmas of the grey residuals. Once the pixels near foreign
  // gradients are out, what is left for the weight are gross outliers (the cores of blobs far
  // from the rim, an occluder's face), so it can be close to least squares: c = 8 keeps 99.4%
  // of the Gaussian efficiency where the usual 4.685 keeps 95% (at 15 grey levels of contrast
  // that was 2-5% of the precision). Without a noise level there is no screen: the usual value.
  const double tukeyC = noiseSigma > 0.0 ? 8.0 : 4.685;

  // One pass over the band at parameters q: residuals (grey - model) and the Jacobian. The band
  // and the Jacobian are kept in columns, one per coordinate or parameter, so that the passes
  // vectorise; the Jacobian's columns of the levels and the ramp (1, x, y) never change.
  std::size_t m = samples.size();
  Eigen::VectorXd px, py, grey, r, rTry, weight;
  Columns jac, jacTry;
  // Pixels the sensor clipped (censored_pixels.hpp).
  CensoredPixels clipped;
  auto loadBand = [&] {
    const auto n = static_cast<Eigen::Index>(m);
    px.resize(n);
    py.resize(n);
    grey.resize(n);
    for (Eigen::Index i = 0; i < n; ++i) {
      px(i) = samples[i].x;
      py(i) = samples[i].y;
      grey(i) = samples[i].grey;
    }
    clipped = CensoredPixels({grey.data(), m}, sensorLimit(image.depth()));
    r.resize(n);
    rTry.resize(n);
    weight.setOnes(n);
    for (Columns* j : {&jac, &jacTry}) {
      j->resize(n, 8);
      j->col(4).setOnes();
      j->col(5) = px;
      j->col(6) = py;
    }
  };
  loadBand();
  bool pixelModel = false;  // the sharp images' model (below): q(3) the lens blur alone
  auto evaluate = [&](const Vector8& q, Eigen::VectorXd& res, Columns& j) {
    if (pixelModel) {
      evaluatePixelProfile(q, static_cast<std::ptrdiff_t>(m), px.data(), py.data(), grey.data(),
                           res.data(), j.col(0).data(), j.col(1).data(), j.col(2).data(),
                           j.col(3).data(), j.col(7).data());
      return;
    }
    evaluateProfile(q, static_cast<std::ptrdiff_t>(m), px.data(), py.data(), grey.data(),
                    res.data(), j.col(0).data(), j.col(1).data(), j.col(2).data(), j.col(3).data(),
                    j.col(7).data());
  };
  auto cost = [&](const Eigen::VectorXd& res) {
    return (weight.array() * res.array().square()).sum();
  };
  Matrix8 jtj;
  Vector8 jtr;
  // J^T W J and J^T W r over the free parameters only; a fixed parameter's row and column are
  // the identity's, so that the step leaves it alone (the ramp is fixed in the first solve, and
  // its products were a quarter of the work). The free columns go through one pass per pair of
  // them (weighted_normal_equations.hpp).
  using Free = std::array<bool, 8>;
  constexpr Free kAll{true, true, true, true, true, true, true, true};
  auto normalEquations = [&](const Free& free) {
    std::array<int, 8> index{};
    std::array<const double*, 8> columns{};
    int k = 0;
    for (int a = 0; a < 8; ++a)
      if (free[a]) {
        index[k] = a;
        columns[k++] = jac.col(a).data();
      }
    std::array<double, 64> h{};
    std::array<double, 8> g{};
    weightedNormalEquations({columns.data(), static_cast<std::size_t>(k)}, weight.data(), r.data(),
                            static_cast<std::ptrdiff_t>(m), h.data(), g.data());
    jtj.setIdentity();
    jtr.setZero();
    for (int u = 0; u < k; ++u) {
      jtr(index[u]) = g[u];
      for (int v = 0; v < k; ++v) jtj(index[u], index[v]) = h[u * k + v];
    }
  };
  auto tukeyWeights = [&] {
    const double sigma = std::max(clipped.robustSigma({r.data(), m}), 0.25);
    tukeyWeight(static_cast<std::ptrdiff_t>(m), r.data(), tukeyC * sigma, weight.data());
    clipped.unweight({r.data(), m}, {weight.data(), m});
    return sigma;
  };

  // Levenberg-Marquardt over the parameters marked free (a fixed one keeps its value).
  double sigma = 0.0;
  auto solve = [&](const Free& free, int maxIterations, bool reweight) {
    LevenbergMarquardtCallbacks problem{
        [&](const Vector8& q) {
          evaluate(q, r, jac);
          clipped.censor({r.data(), m});
          return cost(r);
        },
        [&](int, const Vector8&, Matrix8& h, Vector8& g, double& current) {
          // Robust weights from the start (the starting levels are medians, so clutter already
          // stands out; an unweighted first step lets large dark blobs drag the contrast down),
          // and again at every step (iteratively re-weighted): weights frozen at the start's
          // residuals down-weight the steep rim pixels on one side and hold the fit near its
          // start. With them set in the first two steps only, a sharp disc (lens blur 0.3 px,
          // noise 0.5) measured from a nominal radius 2.5 px too large came out 0.17 px RMS off
          // (0.006 now), and radii on the demo recordings were 0.0045 px small on average
          // (0.0005 now); bench_circle's rows did not move.
          if (reweight) {
            sigma = tukeyWeights();
            current = cost(r);
          }
          normalEquations(free);
          h = jtj;
          g = -jtr;  // the residuals here are grey - model
        },
        [&](const Vector8& q) -> std::optional<double> {
          if (!(q(3) > 0.05)) return std::nullopt;
          evaluate(q, rTry, jacTry);
          clipped.censor({rTry.data(), m});
          return cost(rTry);
        },
        [&] {
          std::swap(r, rTry);
          std::swap(jac, jacTry);
        },
        // Done once a step moves the rim by less than 1e-3 px: the next would move it by far
        // less (1e-4 px and below).
        // A solve that starts at a converged fit (the ramp's, the refit without contaminated
        // sectors) stops after two steps instead of three.
        [](int it, const Vector8& step) { return it >= 1 && step.head<4>().norm() < 1e-3; }};
    const LevenbergMarquardtSettings settings{.maxIterations = maxIterations,
                                              .maxTries = 6,
                                              .initialDamping = 1e-4,
                                              .dampingDecrease = 0.3,
                                              .minDamping = 1e-9};
    return levenbergMarquardt(problem, p, settings) != LevenbergMarquardtStop::NonFiniteStep;
  };

  // Without the illumination ramp first: in a thin band a ramp resembles a shifted rim, and
  // fitting one costs about half the precision of a small circle. A score test at that solution
  // (chi-square of the ramp's gradient, 2 degrees of freedom, 99.9%) decides whether the image
  // has a ramp worth fitting. The block of the other parameters is the last step's (the solve
  // ends once a step moves the rim by under 1e-3 px, so it hardly differs at the solution); only
  // the ramp's two rows are computed here, at the solution: the full matrix again cost as much as
  // one and a half of the solve's own.
  bool withRamp = false;
  // A clipped rim's levels beyond the limit come from the slope of its step, slowly: its steps
  // along the valley of level, blur and radius took up to 30 iterations.
  const int firstSolveIterations = clipped.empty() ? 10 : 40;
  if (!solve({true, true, true, true, true, false, false, true}, firstSolveIterations, true))
    return std::nullopt;
  {
    constexpr int kRamp[2] = {5, 6};
    constexpr int kRest[6] = {0, 1, 2, 3, 4, 7};
    Eigen::Matrix<double, 6, 6> hoo;
    for (int u = 0; u < 6; ++u)
      for (int v = 0; v < 6; ++v) hoo(u, v) = jtj(kRest[u], kRest[v]);
    // Rows of the ramp against the ramp and the rest: columns (ramp x, ramp y, rest...).
    std::array<const double*, 8> columns{};
    for (int u = 0; u < 2; ++u) columns[u] = jac.col(kRamp[u]).data();
    for (int v = 0; v < 6; ++v) columns[2 + v] = jac.col(kRest[v]).data();
    std::array<double, 64> h{};
    std::array<double, 8> g{};
    weightedNormalEquationsLeadingPair(columns, weight.data(), r.data(),
                                       static_cast<std::ptrdiff_t>(m), h.data(), g.data());
    Eigen::Matrix2d hgg;
    Eigen::Matrix<double, 2, 6> hgo;
    Eigen::Vector2d score;
    for (int u = 0; u < 2; ++u) {
      score(u) = g[u];
      for (int v = 0; v < 2; ++v) hgg(u, v) = h[u * 8 + v];
      for (int v = 0; v < 6; ++v) hgo(u, v) = h[u * 8 + 2 + v];
    }
    const Eigen::Matrix2d schur = hgg - hgo * hoo.ldlt().solve(hgo.transpose());
    const double statistic = score.dot(schur.ldlt().solve(score)) / std::max(sigma * sigma, 1e-12);
    if (std::isfinite(statistic) && statistic > 13.8) {
      withRamp = true;
      if (!solve(kAll, 10, true)) return std::nullopt;
    }
  }

  // Sectors whose residuals are too large for the noise leave the fit, which is then repeated: a
  // clutter blob or an occluder's border blurred into the band, too faint or too close to the rim
  // for the edge points to flag, biases a small circle by several hundredths of a pixel while
  // each of its pixels stays within the Tukey weight's reach. The refit only pays when the
  // flagged sectors hold a noticeable share of the pixels: a stray bin of a long rim (chance, or a
  // blob on a big circle) moves the centre by far less than the bound and would cost a solve.
  const std::vector<std::uint8_t> bad = contaminatedBins(samples, {r.data(), m}, bins);
  std::size_t kept = 0;
  for (std::size_t i = 0; i < m; ++i)
    if (!bad[samples[i].bin]) ++kept;
  if (static_cast<double>(m - kept) >= kMinRefitShare * static_cast<double>(m)) {
    if (kept < 30) return std::nullopt;
    kept = 0;
    for (std::size_t i = 0; i < m; ++i)
      if (!bad[samples[i].bin]) samples[kept++] = samples[i];
    samples.resize(kept);
    m = kept;
    loadBand();
    if (!solve({true, true, true, true, true, withRamp, withRamp, true}, 10, true))
      return std::nullopt;
  }

  // A sharp image (a lens blur of a third of a pixel or less): the pixel's box dominates the
  // profile, which the Gaussian misfits by several grey levels at high contrast; the robust
  // weights then reject the steepest pixels, unevenly around the rim. A perfectly sharp disc at
  // noise 0.5 came out 0.28 px RMS off (0.015 at noise 1). Refit from there with the pixel's
  // area in the model; its blur parameter is the lens's alone.
  if (p(3) < step_profile::kSharpBlur) {
    pixelModel = true;
    p(3) = step_profile::lensBlurOf(p(3));
    if (!solve({true, true, true, true, true, withRamp, withRamp, true}, 15, true))
      return std::nullopt;
  }
  // The equivalent Gaussian blur, PSF and pixel together: its variance across the rim is what
  // moves the 50% level inside a convex rim (below).
  const double blur = pixelModel ? step_profile::equivalentBlur(p(3)) : p(3);
  const cv::Vec2d shift = elliptic ? toCircle.inv() * cv::Vec2d(p(0), p(1)) : cv::Vec2d(p(0), p(1));
  const cv::Point2d c{centre.x + shift[0], centre.y + shift[1]};
  if (!p.allFinite() || blur < 0.2 || blur > 5.0 || p(2) <= 0.0 ||
      std::hypot(c.x - centre.x, c.y - centre.y) > maxShift || std::abs(p(2) - radius) > maxShift)
    return std::nullopt;
  if (!clipped.middleSeen(p(4), p(7))) return std::nullopt;
  CircleProfileFit fit;
  fit.centre = c;
  fit.blur = blur;
  fit.radius = p(2) + blur * blur / (2.0 * p(2));
  fit.noise = sigma;
  fit.pixels = static_cast<int>(samples.size());
  fit.clipped = static_cast<int>(clipped.size());
  if (fitRimShape) {
    // |exp(S) u| = rho + (a (x^2 - y^2) + 2 c x y) / rho to first order: the columns of a and c
    // are d/drho's (minus d/dR's) times those factors. Their score and step against the free
    // parameters' fit, the latter's block eliminated (the Schur complement), as the ramp's above:
    // the block is the last step's and the free parameters' own score is taken as zero (the
    // solve has converged), so that one pass over the band computes the rest.
    Eigen::VectorXd harmonicA(static_cast<Eigen::Index>(m)), harmonicC(harmonicA.size());
    secondHarmonicColumns(p, harmonicA.size(), px.data(), py.data(), jac.col(2).data(),
                          harmonicA.data(), harmonicC.data());
    const std::array<int, 8> free{0, 1, 2, 3, 4, 7, 5, 6};
    const int k = withRamp ? 8 : 6;
    Eigen::MatrixXd hho(2, k), hoo(k, k);
    Eigen::Vector2d score;
    Eigen::Matrix2d hhh;
    // At most 8 columns a pass: the harmonics and six of the others, then the ramp's two.
    for (int first = 0; first < k; first += 6) {
      const int count = std::min(6, k - first);
      std::array<const double*, 8> columns{harmonicA.data(), harmonicC.data()};
      for (int v = 0; v < count; ++v) columns[2 + v] = jac.col(free[first + v]).data();
      std::array<double, 64> h{};
      std::array<double, 8> g{};
      const auto width = static_cast<std::size_t>(2 + count);
      weightedNormalEquationsLeadingPair({columns.data(), width}, weight.data(), r.data(),
                                         static_cast<std::ptrdiff_t>(m), h.data(), g.data());
      for (int u = 0; u < 2; ++u) {
        score(u) = g[u];
        for (int v = 0; v < 2; ++v) hhh(u, v) = h[u * width + v];
        for (int v = 0; v < count; ++v) hho(u, first + v) = h[u * width + 2 + v];
      }
    }
    for (int u = 0; u < k; ++u)
      for (int v = 0; v < k; ++v) hoo(u, v) = jtj(free[u], free[v]);
    const Eigen::Matrix2d schur = hhh - hho * hoo.ldlt().solve(hho.transpose());
    const Eigen::Vector2d step = schur.ldlt().solve(score);
    const double variance = std::max(sigma * sigma, 1e-12);
    fit.secondHarmonic = score.dot(step) / variance;
    if (step.allFinite()) {
      fit.shapeStep = {step(0), step(1)};
      fit.shapeInformation = {schur(0, 0) / variance, schur(0, 1) / variance,
                              schur(1, 0) / variance, schur(1, 1) / variance};
    }
  }
  return fit;
}

}  // namespace facet
