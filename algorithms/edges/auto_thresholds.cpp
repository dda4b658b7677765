#include "algorithms/edges/auto_thresholds.hpp"

#include <algorithm>
#include <array>
#include <stdexcept>

namespace facet {
namespace {

constexpr int kBins = 256;

// Otsu: the bin boundary maximising the between-class variance.
int otsuBin(const std::array<double, kBins>& hist) {
  double total = 0, sum = 0;
  for (int i = 0; i < kBins; ++i) {
    total += hist[i];
    sum += i * hist[i];
  }
  double w0 = 0, sum0 = 0, best = -1;
  int bestBin = 0;
  for (int t = 0; t < kBins - 1; ++t) {
    w0 += hist[t];
    sum0 += t * hist[t];
    const double w1 = total - w0;
    if (w0 <= 0 || w1 <= 0) continue;
    const double m0 = sum0 / w0, m1 = (sum - sum0) / w1;
    const double between = w0 * w1 * (m0 - m1) * (m0 - m1);
    if (between > best) {
      best = between;
      bestBin = t;
    }
  }
  return bestBin;
}

}  // namespace

CannyThresholds autoCannyThresholds(const cv::Mat& magnitude, const cv::Mat& mask,
                                    const AutoThresholdParams& params) {
  if (magnitude.type() != CV_32FC1)
    throw std::invalid_argument("autoCannyThresholds: magnitude must be CV_32FC1");
  if (!mask.empty() && (mask.size() != magnitude.size() || mask.type() != CV_8UC1))
    throw std::invalid_argument("autoCannyThresholds: mask must be CV_8UC1 of the same size");

  float maxMag = 0;
  for (int y = 0; y < magnitude.rows; ++y) {
    const auto* m = magnitude.ptr<float>(y);
    const uchar* k = mask.empty() ? nullptr : mask.ptr<uchar>(y);
    for (int x = 0; x < magnitude.cols; ++x)
      if (!k || k[x]) maxMag = std::max(maxMag, m[x]);
  }
  CannyThresholds t;
  if (maxMag <= 0) {
    t.high = params.minHigh;
    t.low = params.lowRatio * t.high;
    return t;
  }
  std::array<double, kBins> hist{};
  const double binWidth = maxMag / (kBins - 1);
  for (int y = 0; y < magnitude.rows; ++y) {
    const auto* m = magnitude.ptr<float>(y);
    const uchar* k = mask.empty() ? nullptr : mask.ptr<uchar>(y);
    for (int x = 0; x < magnitude.cols; ++x)
      if (!k || k[x]) hist[static_cast<int>(m[x] / binWidth + 0.5)] += 1;
  }
  double count = 0;
  for (double h : hist) count += h;
  double cumulative = 0;
  int medianBin = 0;
  for (; medianBin < kBins; ++medianBin) {
    cumulative += hist[medianBin];
    if (cumulative >= 0.5 * count) break;
  }
  const double noiseSigma = medianBin * binWidth / 1.18;
  const double otsu = (otsuBin(hist) + 0.5) * binWidth;
  t.high = std::max({otsu, params.noiseFactor * noiseSigma, params.minHigh});
  t.low = params.lowRatio * t.high;
  return t;
}

}  // namespace facet
