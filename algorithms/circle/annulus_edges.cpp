#include "algorithms/circle/annulus_edges.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <numbers>

#include "algorithms/circle/diamond_angle.hpp"
#include "algorithms/edges/canny.hpp"
#include "algorithms/edges/facet_model.hpp"

namespace facet {
namespace {

// Noise gain of the 5x5 Sobel derivative normalised to grey levels per pixel: derivative taps
// [-1 -2 0 2 1] / 8 and smoothing taps [1 4 6 4 1] / 16 give sqrt(10) / 8 * sqrt(70) / 16.
const double kGradientNoiseGain = std::sqrt(10.0) / 8.0 * std::sqrt(70.0) / 16.0;

double median(std::vector<float>& v) {
  if (v.empty()) return 0.0;
  std::nth_element(v.begin(), v.begin() + v.size() / 2, v.end());
  return v[v.size() / 2];
}

// The same element as median() of non-negative integers below `bound`, by counting them: a
// selection's comparisons branch on the data, and the noise mask's responses on an 8-bit image
// are whole numbers of at most 16 x 255.
int medianByCounting(const std::vector<int>& v, int bound) {
  if (v.empty()) return 0;
  // Counters up to the largest value only (zeroing all of `bound` cost more than the counting).
  std::vector<int> count(std::min(bound, *std::max_element(v.begin(), v.end()) + 1), 0);
  for (int a : v) ++count[a];
  const std::size_t rank = v.size() / 2;  // median(): the element at index size / 2 once sorted
  std::size_t below = 0;
  int value = 0;
  while (below + static_cast<std::size_t>(count[value]) <= rank) below += count[value++];
  return value;
}

// The largest gradient magnitude in each angular sector and Immerkaer's noise response on every
// third pixel of the annulus (its absolute value, in the image's own grey levels); whether a mask
// met a clipped pixel.
template <typename T>
bool annulusStatistics(const cv::Mat& image, const EdgeGradient& gradient, const RowRuns& runs,
                       cv::Point2d centre, std::vector<float>& peak, std::vector<int>& noise) {
  const int sectors = static_cast<int>(peak.size());
  const cv::Rect crop = gradient.area;
  std::vector<int> sector;  // of each pixel of a run
  for (const RowRun& run : runs) {
    const int y = run.y;
    const double dy = y - centre.y;
    const float* magnitude = gradient.magnitude.ptr<float>(y - crop.y) - crop.x;
    sector.resize(static_cast<std::size_t>((run.x1 - run.x0 + 3) & ~3));  // rowBins' groups
    diamond_angle::rowBins(run.x0, run.x1 - run.x0, centre.x, dy, sectors, sector.data());
    for (int x = run.x0; x < run.x1; ++x) {
      float& sectorPeak = peak[sector[x - run.x0]];
      sectorPeak = std::max(sectorPeak, magnitude[x]);
    }
  }
  // Immerkaer's noise mask (its taps' squares sum to 36), on every third pixel: plenty for a
  // median. Not where the sensor clipped a pixel of the mask: there the noise is clipped away (an
  // overexposed backlight filling half the annulus gave a median of 0, and Canny thresholds and
  // the grey fit's screens at their floors). A clipped region of the annulus holds a mask's
  // centre, so only an annulus with a clipped centre has its masks tested pixel by pixel (the
  // test cost 2% of a measurement).
  constexpr T kClip = std::numeric_limits<T>::max();
  auto clipped = [](const T* row, int x) {
    return std::min({row[x - 1], row[x], row[x + 1]}) == 0 ||
           std::max({row[x - 1], row[x], row[x + 1]}) == kClip;
  };
  // Every mask first, noting whether a centre was clipped; only then are the masks tested pixel
  // by pixel and taken again.
  auto response = [](const T* above, const T* here, const T* below, int x) {
    return std::abs(above[x - 1] - 2 * above[x] + above[x + 1] - 2 * here[x - 1] + 4 * here[x] -
                    2 * here[x + 1] + below[x - 1] - 2 * below[x] + below[x + 1]);
  };
  bool anyClipped = false;
  for (const RowRun& run : runs) {
    const int y = run.y;
    const T* above = image.ptr<T>(y - 1);
    const T* here = image.ptr<T>(y);
    const T* below = image.ptr<T>(y + 1);
    for (int x = run.x0 + ((3 - (run.x0 + y) % 3) % 3); x < run.x1; x += 3) {
      anyClipped |= here[x] == 0 || here[x] == kClip;
      noise.push_back(response(above, here, below, x));
    }
  }
  if (!anyClipped) return false;
  noise.clear();
  for (const RowRun& run : runs) {
    const int y = run.y;
    const T* above = image.ptr<T>(y - 1);
    const T* here = image.ptr<T>(y);
    const T* below = image.ptr<T>(y + 1);
    for (int x = run.x0 + ((3 - (run.x0 + y) % 3) % 3); x < run.x1; x += 3)
      if (!clipped(above, x) && !clipped(here, x) && !clipped(below, x))
        noise.push_back(response(above, here, below, x));
  }
  return true;
}

}  // namespace

AnnulusEdges detectAnnulusEdges(const cv::Mat& image, cv::Point2d centre, double rIn, double rOut,
                                std::optional<double> low, std::optional<double> high) {
  AnnulusEdges out;
  // The annulus' bounding box plus the Facet window's margin, clipped to the image.
  constexpr int kMargin = 4;
  const cv::Rect box(static_cast<int>(std::floor(centre.x - rOut)) - kMargin,
                     static_cast<int>(std::floor(centre.y - rOut)) - kMargin,
                     static_cast<int>(2 * rOut) + 2 * kMargin + 3,
                     static_cast<int>(2 * rOut) + 2 * kMargin + 3);
  const cv::Rect crop = box & cv::Rect(0, 0, image.cols, image.rows);
  if (crop.width < 5 || crop.height < 5) return out;

  // Annulus pixels that carry a full 5x5 window inside the image (and inside the crop). Only
  // they and their neighbours get a gradient: a thin annulus is a small part of its box.
  const int xLo = std::max(2, crop.x + 2), xHi = std::min(image.cols - 3, crop.br().x - 3);
  const int yLo = std::max(2, crop.y + 2), yHi = std::min(image.rows - 3, crop.br().y - 3);
  const RowRuns runs =
      annulusRowRuns(centre, rIn, rOut, cv::Rect(xLo, yLo, xHi - xLo + 1, yHi - yLo + 1));
  for (const RowRun& run : runs) out.annulusPixels += run.x1 - run.x0;
  if (out.annulusPixels == 0) return out;

  const double scale = image.depth() == CV_16U ? 1.0 / 256.0 : 1.0;
  const int sectors = std::clamp(static_cast<int>(2.0 * std::numbers::pi * rOut / 6.0), 8, 120);
  const EdgeGradient gradient = computeEdgeGradientOnRuns(image, crop, runs);
  std::vector<float> peak(sectors, 0.0f);
  std::vector<int> noise;
  noise.reserve(out.annulusPixels / 3 + runs.size());
  int noiseMedian = 0;
  if (image.depth() == CV_16U) {
    out.clipped = annulusStatistics<std::uint16_t>(image, gradient, runs, centre, peak, noise);
    if (!noise.empty()) {
      std::nth_element(noise.begin(), noise.begin() + noise.size() / 2, noise.end());
      noiseMedian = noise[noise.size() / 2];
    }
  } else {
    out.clipped = annulusStatistics<std::uint8_t>(image, gradient, runs, centre, peak, noise);
    noiseMedian = medianByCounting(noise, 16 * 255 + 1);
  }
  // Scaled once: the same value as scaling each response (the scale is a power of two).
  out.noiseSigma = noiseMedian * scale / (0.6745 * 6.0);
  if (low && high) {
    out.lowThreshold = *low;
    out.highThreshold = *high;
  } else {
    std::vector<float> used;
    for (float v : peak)
      if (v > 0.0f) used.push_back(v);
    const double rim = median(used);
    const double sigmaG = out.noiseSigma * kGradientNoiseGain;
    out.highThreshold = std::max({0.5 * rim, 4.5 * sigmaG, 0.5});
    out.lowThreshold = std::max(0.4 * out.highThreshold, 2.5 * sigmaG);
  }

  // Edge pixels can only lie on the runs: visiting them row by row keeps the points in the
  // image's row-major order.
  const cv::Mat edges = cannyOnRuns(gradient, out.lowThreshold, out.highThreshold, runs);
  out.points.reserve(static_cast<std::size_t>(out.annulusPixels) / 8);  // a rim: about 1 in 11
  for (const RowRun& run : runs) {
    const auto* e = edges.ptr<std::uint8_t>(run.y - crop.y) - crop.x;
    auto edgePoint = [&](int x) {
      if (auto point = facetEdgePoint(image, cv::Point(x, run.y))) out.points.push_back(*point);
    };
    // About one pixel in ten is an edge: eight map bytes at a time, from one edge to the next.
    int x = run.x0;
    for (std::uint64_t eight = 0; x + 8 <= run.x1;) {
      std::memcpy(&eight, e + x, 8);
      if (eight == 0) {
        x += 8;
        continue;
      }
      // The first edge among them: the lowest non-zero byte in memory order.
      x += (std::endian::native == std::endian::little ? std::countr_zero(eight)
                                                       : std::countl_zero(eight)) /
           8;
      edgePoint(x++);
    }
    for (; x < run.x1; ++x)
      if (e[x]) edgePoint(x);
  }
  return out;
}

}  // namespace facet
