#include "algorithms/circle/rim_band.hpp"

#include "algorithms/circle/pixel_pass.hpp"
#include "algorithms/circle/step_profile.hpp"
#include "algorithms/edges/row_runs.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <memory>
#include <numbers>
#include <span>
#include <tuple>
#include <utility>

namespace facet::rim_band {

namespace {

// The value of rank k among v[0, n), as std::nth_element would place it at k, for values without
// a NaN. Three-way partitions around a median of three, each element going to the lower part, the
// upper part (in `scratch`) or neither (equal to the pivot) without a branch: std::nth_element's
// comparisons mispredicted about once in three elements (random residuals, levels), which cost
// more time than its instructions. `scratch` holds room for n values; both buffers are clobbered.
double valueOfRank(double* v, double* scratch, std::size_t n, std::size_t k) {
  while (n > 1) {
    const double a = v[0], b = v[n / 2], c = v[n - 1];
    const double pivot = std::max(std::min(a, b), std::min(std::max(a, b), c));
    std::size_t below = 0, above = 0;
    for (std::size_t i = 0; i < n; ++i) {
      const double x = v[i];
      v[below] = x;  // i >= below: x has been read
      scratch[above] = x;
      below += x < pivot;
      above += pivot < x;
    }
    if (k < below) {
      n = below;
    } else if (k < n - above) {
      return pivot;  // one of the values equal to it
    } else {
      k -= n - above;
      n = above;
      std::swap(v, scratch);
    }
  }
  return v[0];
}

}  // namespace

double medianOf(std::vector<double> v) {
  if (v.empty()) return 0.0;
  const std::size_t k = v.size() / 2;
  if (std::any_of(v.begin(), v.end(), [](double x) { return std::isnan(x); })) {
    std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(k), v.end());
    return v[k];
  }
  const auto scratch = std::make_unique_for_overwrite<double[]>(v.size());
  return valueOfRank(v.data(), scratch.get(), v.size(), k);
}

namespace {

template <typename T>
double clippedShareOf(const cv::Mat& image, const RowRuns& runs) {
  constexpr T limit = std::numeric_limits<T>::max();
  std::size_t clipped = 0, all = 0;
  for (const RowRun& run : runs) {
    if (run.x1 <= run.x0) continue;
    const T* row = image.ptr<T>(run.y);
    for (int x = run.x0; x < run.x1; ++x) clipped += row[x] == limit || row[x] == 0;
    all += static_cast<std::size_t>(run.x1 - run.x0);
  }
  return all == 0 ? 0.0 : static_cast<double>(clipped) / static_cast<double>(all);
}

}  // namespace

double clippedShare(const cv::Mat& image, cv::Point2d centre, double rIn, double rOut) {
  const RowRuns runs =
      annulusRowRuns(centre, std::max(0.0, rIn), rOut, cv::Rect(0, 0, image.cols, image.rows));
  return image.depth() == CV_16U ? clippedShareOf<std::uint16_t>(image, runs)
                                 : clippedShareOf<std::uint8_t>(image, runs);
}

double pixelsNeeded(double snr, double halfWidth) {
  constexpr double kTargetSigma = 0.0035;
  const double infoPerPixel =
      snr * snr / (2.0 * std::sqrt(std::numbers::pi) * 1.05) / (4.0 * halfWidth);
  return std::max(1000.0, 1.0 / (kTargetSigma * kTargetSigma * infoPerPixel));
}

std::vector<std::uint8_t> closedCoverage(const std::vector<std::uint8_t>& covered, int margin) {
  const int bins = static_cast<int>(covered.size());
  // The coverage around the circle as a row that repeats it `pad` bins beyond either end, so that
  // the tests below read neighbours without wrapping each index.
  const int pad = margin + 2;
  std::vector<std::uint8_t> around(static_cast<std::size_t>(bins + 2 * pad));
  for (int k = 0; k < bins + 2 * pad; ++k)
    around[static_cast<std::size_t>(k)] =
        covered[static_cast<std::size_t>(((k - pad) % bins + bins) % bins)] != 0;
  const std::uint8_t* at = around.data() + pad;  // at[i]: bin i, i in [-pad, bins + pad)
  // Gaps of up to 2 bins closed, for bins [-margin, bins + margin).
  std::vector<std::uint8_t> closedAround(static_cast<std::size_t>(bins + 2 * margin));
  for (int i = -margin; i < bins + margin; ++i)
    closedAround[static_cast<std::size_t>(i + margin)] =
        at[i] || ((at[i - 1] || at[i - 2]) && (at[i + 1] || at[i + 2]));
  const std::uint8_t* closed = closedAround.data() + margin;
  std::vector<std::uint8_t> kept(covered.size(), 0);
  for (int i = 0; i < bins; ++i) {
    bool inside = true;
    for (int k = -margin; k <= margin && inside; ++k) inside = closed[i + k] != 0;
    kept[static_cast<std::size_t>(i)] = inside ? 1 : 0;
  }
  return kept;
}

ForeignReach::ForeignReach(const std::vector<EdgePoint>& foreign, double noiseSigma, cv::Rect box)
    : box_(box) {
  if (foreign.empty() || box.width <= 0 || box.height <= 0) return;
  constexpr double kEdgeBlur = 1.0;  // pixels; a sharp edge seen through the pixel grid
  constexpr double kMinReach = 2.0, kMaxReach = 4.0;                    // pixels
  const double tolerance = noiseSigma > 0.0 ? 0.25 * noiseSigma : 0.5;  // grey levels
  map_.create(box.height, box.width, CV_8U);
  marked_.assign(static_cast<std::size_t>(box.height), 0);
  const int x1 = box.x + box.width - 1, y1 = box.y + box.height - 1;
  for (const EdgePoint& e : foreign) {
    // The step's height follows from the edge's gradient magnitude (a step b blurred by s peaks
    // at b / (sqrt(2 pi) s)); a fixed 2 px let the halo of a high-contrast blob next to the rim
    // (several grey levels there, radial like the rim's own gradient) into the fit.
    const double step = e.magnitude * std::sqrt(2.0 * std::numbers::pi) * kEdgeBlur;
    auto halo = [&](double d) {  // grey change d px from the edge
      const double z = d / kEdgeBlur;
      return step * step_profile::upperTail(z, std::exp(-0.5 * z * z));
    };
    double reach = kMinReach;
    while (reach < kMaxReach && halo(reach) > tolerance) reach += 0.25;
    const cv::Point2d q = e.position;
    const int qx = static_cast<int>(std::lround(q.x)), qy = static_cast<int>(std::lround(q.y));
    const int span = static_cast<int>(std::ceil(reach));
    for (int v = std::max(box.y, qy - span); v <= std::min(y1, qy + span); ++v) {
      const auto r = static_cast<std::size_t>(v - box.y);
      if (!marked_[r]) {
        std::memset(map_.ptr<std::uint8_t>(v - box.y), 0, static_cast<std::size_t>(map_.cols));
        marked_[r] = 1;
      }
      for (int u = std::max(box.x, qx - span); u <= std::min(x1, qx + span); ++u)
        if ((u - q.x) * (u - q.x) + (v - q.y) * (v - q.y) <= reach * reach)
          map_.at<std::uint8_t>(v - box.y, u - box.x) = 1;
    }
  }
}

// Robust sigma (1.4826 x median absolute value) of residuals around zero, from an evenly strided
// subset of at most kScaleSamples: it only scales the Tukey weight and the sector test, where a
// few percent do not matter, and the median of all of a big rim's residuals cost a tenth of the
// measurement.
double robustSigma(std::span<const double> residuals) {
  constexpr std::size_t kScaleSamples = 512;
  const std::size_t stride = std::max<std::size_t>(1, residuals.size() / kScaleSamples);
  std::vector<double> a;
  a.reserve(residuals.size() / stride + 1);
  for (std::size_t i = 0; i < residuals.size(); i += stride) a.push_back(std::abs(residuals[i]));
  return 1.4826 * medianOf(std::move(a));
}

// Angular bins whose grey residuals are too large for the noise. Per bin, the mean of the squared
// residuals (each capped at 3 sigma, so one stray pixel does not condemn its bin) is compared
// with the median over all bins, the noise level of a clean rim including the model's own misfit;
// a bin above it by more than kSectorZ standard errors of a chi-square mean is contaminated.
std::vector<std::uint8_t> contaminatedBins(const std::vector<Sample>& samples,
                                           std::span<const double> residuals, int bins) {
  constexpr double kSectorZ = 4.0;
  std::vector<double> sum(bins, 0.0), count(bins, 0.0);
  const double cap = 6.0 * robustSigma(residuals);
  for (std::size_t i = 0; i < samples.size(); ++i) {
    const double a = std::min(std::abs(residuals[i]), cap);
    sum[samples[i].bin] += a * a;
    count[samples[i].bin] += 1.0;
  }
  std::vector<double> means;
  for (int b = 0; b < bins; ++b)
    if (count[b] >= 4.0) means.push_back(sum[b] / count[b]);
  std::vector<std::uint8_t> bad(bins, 0);
  if (means.size() < 8) return bad;
  const double reference = medianOf(means);
  for (int b = 0; b < bins; ++b)
    if (count[b] > 0.0 &&
        sum[b] / count[b] > reference * (1.0 + kSectorZ * std::sqrt(2.0 / count[b])))
      bad[b] = 1;
  return bad;
}

namespace {

// The 3x3 Sobel gradient's taps at pixel (x, y), summed in integers: (x, y) components, 8 times
// the unit-gain derivative in the image's grey levels.
template <typename T>
std::pair<int, int> sobel3(const T* image, std::ptrdiff_t step, int x, int y) {
  const T* b = image + y * step + x;
  const T* a = b - step;
  const T* c = b + step;
  return {a[1] + 2 * b[1] + c[1] - a[-1] - 2 * b[-1] - c[-1],
          c[-1] + 2 * c[0] + c[1] - a[-1] - 2 * a[0] - a[1]};
}

// Whether the gradient of each of n samples is foreign to the rim (see dropForeignGradients): its
// Sobel taps (tapsX, tapsY), its offset (x, y) from the centre. `scale` takes the taps to the
// 8-bit scale; they are scaled once: the same value as scaling each (the scale is a power of two
// and every sum is exact). Elementwise, a pass of its own so that it vectorises.
FACET_PIXEL_PASS void foreignGradients(std::ptrdiff_t n, const int* __restrict tapsX,
                                       const int* __restrict tapsY, const double* __restrict x,
                                       const double* __restrict y, double scale, double radius,
                                       double noiseSigma, std::uint8_t* __restrict foreign) {
  constexpr double kGradientZ = 4.0;
  constexpr double kFlatZone = 3.0;  // pixels from the rim: the blurred edge's slope is < 1% there
  // The 3x3 Sobel divided by 8 is a unit-gain derivative; its noise is sqrt(12) / 8 of the pixels'.
  const double limit = kGradientZ * noiseSigma * std::sqrt(12.0) / 8.0;
  // The rim's own gradient, seen by the 3x3 Sobel on a sharp step (a sharp lens, an exact render),
  // turns by up to several degrees from the normal with the step's place in the pixel: a
  // tangential share of the rim's own magnitude, not a foreign gradient. sin(10 degrees).
  constexpr double kSobelTurn = 0.17;
  for (std::ptrdiff_t i = 0; i < n; ++i) {
    const double gx = tapsX[i] * scale / 8.0, gy = tapsY[i] * scale / 8.0;
    const double dx = x[i], dy = y[i];
    const double rho = std::max(std::sqrt(dx * dx + dy * dy), 1e-9);
    const double tangential = (gy * dx - gx * dy) / rho;
    // Both tests, then a choice without a branch: which one applies (the narrow band reaches
    // 4 px from the rim) follows no pattern the branch predictor learns.
    const bool far = std::abs(rho - radius) > kFlatZone;
    const bool steep = gx * gx + gy * gy > limit * limit;
    const bool across = std::abs(tangential) > limit + kSobelTurn * std::sqrt(gx * gx + gy * gy);
    foreign[i] = (far & steep) | (!far & across);
  }
}

// `border`: the box reaches the image's outermost pixels, which have no 3x3 neighbourhood.
template <typename T, bool border>
void dropForeign(std::vector<Sample>& samples, const cv::Mat& image, double radius,
                 double noiseSigma, cv::Rect box, double scale) {
  // The samples' Sobel taps and offsets in columns, for the vectorised test. Left uninitialised:
  // every entry is written before it is read (zeroing them cost a fifth of this screen).
  const auto n = static_cast<std::ptrdiff_t>(samples.size());
  const auto tapsX = std::make_unique_for_overwrite<int[]>(samples.size());
  const auto tapsY = std::make_unique_for_overwrite<int[]>(samples.size());
  const auto x = std::make_unique_for_overwrite<double[]>(samples.size());
  const auto y = std::make_unique_for_overwrite<double[]>(samples.size());
  const auto foreign = std::make_unique_for_overwrite<std::uint8_t[]>(samples.size());
  const T* pixels = image.ptr<T>(0);
  const auto step = static_cast<std::ptrdiff_t>(image.step1());
  for (std::ptrdiff_t i = 0; i < n; ++i) {
    const Sample& e = samples[static_cast<std::size_t>(i)];
    // A pixel without a 3x3 neighbourhood has taps 0 (and is never marked, below).
    if (!border ||
        (e.column >= 1 && e.row >= 1 && e.column < image.cols - 1 && e.row < image.rows - 1))
      std::tie(tapsX[i], tapsY[i]) = sobel3(pixels, step, e.column, e.row);
    else
      tapsX[i] = tapsY[i] = 0;
    x[i] = e.x;
    y[i] = e.y;
  }
  foreignGradients(n, tapsX.get(), tapsY.get(), x.get(), y.get(), scale, radius, noiseSigma,
                   foreign.get());
  // The flag map only when some pixel is foreign: a clean rim needs none. A row of it is zeroed
  // when first marked (zeroing the whole map cost a quarter of this screen); a row not zeroed
  // holds no flag.
  cv::Mat flagged;
  std::vector<std::uint8_t> flaggedRow;  // 1: the row of `flagged` is zeroed and marked
  for (std::ptrdiff_t i = 0; i < n; ++i) {
    if (!foreign[i]) continue;
    const int x = samples[static_cast<std::size_t>(i)].column;
    const int y = samples[static_cast<std::size_t>(i)].row;
    if (border && (x < 1 || y < 1 || x >= image.cols - 1 || y >= image.rows - 1)) continue;
    if (flagged.empty()) {
      flagged.create(box.height + 2, box.width + 2, CV_8U);  // 1 px margin
      flaggedRow.assign(box.height + 2, 0);
    }
    for (int v = -1; v <= 1; ++v) {
      const int row = y - box.y + 1 + v;
      if (!flaggedRow[row]) {
        std::memset(flagged.ptr<std::uint8_t>(row), 0, static_cast<std::size_t>(flagged.cols));
        flaggedRow[row] = 1;
      }
      for (int u = -1; u <= 1; ++u) flagged.at<std::uint8_t>(row, x - box.x + 1 + u) = 1;
    }
  }
  if (flagged.empty()) return;
  std::erase_if(samples, [&](const Sample& e) {
    const int row = e.row - box.y + 1;
    return flaggedRow[row] && flagged.at<std::uint8_t>(row, e.column - box.x + 1) != 0;
  });
}

}  // namespace

// Removes the samples whose pixel, or a neighbour among the samples, has a grey-value gradient
// the blurred rim cannot explain. The rim's gradient is radial, and more than kFlatZone px from
// the rim the model is flat but for the illumination ramp (below 1 grey level per pixel); so a
// tangential gradient anywhere, or any gradient far from the rim, beyond kGradientZ standard
// deviations of the gradient's noise belongs to something else: a clutter blob or an occluder's
// border, too faint for the edge points or outside their annulus, or the blurred tail of one.
// Each such pixel is within the Tukey weight's reach of the model and pulls the rim. Unlike a
// test on the residuals, this one does not depend on the fit being right (a circle pulled by
// clutter leaves coherent residuals along its own rim). The neighbours go too: a blurred blob's
// tail is still a few grey levels high where its gradient has sunk into the noise.
void dropForeignGradients(std::vector<Sample>& samples, const cv::Mat& image, double radius,
                          double noiseSigma, cv::Rect box) {
  const bool border =
      box.x < 1 || box.y < 1 || box.br().x > image.cols - 1 || box.br().y > image.rows - 1;
  const bool wide = image.depth() == CV_16U;
  const double scale = wide ? 1.0 / 256.0 : 1.0;
  if (wide && border)
    dropForeign<std::uint16_t, true>(samples, image, radius, noiseSigma, box, scale);
  else if (wide)
    dropForeign<std::uint16_t, false>(samples, image, radius, noiseSigma, box, scale);
  else if (border)
    dropForeign<std::uint8_t, true>(samples, image, radius, noiseSigma, box, scale);
  else
    dropForeign<std::uint8_t, false>(samples, image, radius, noiseSigma, box, scale);
}

}  // namespace facet::rim_band
