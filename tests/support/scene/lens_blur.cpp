#include "tests/support/scene/lens_blur.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

namespace facet::scene {
namespace {

constexpr int kLensSubrows = 256;  // sub-scanlines per fine row

double normalCdf(double x) {
  return 0.5 * std::erfc(-x / std::numbers::sqrt2);
}
double normalPdf(double x) {
  return std::exp(-0.5 * x * x) / std::sqrt(2 * std::numbers::pi);
}

// Weights of the fine cells d = m - i*scale (m fine index, i pixel index) for pixel i, d in
// [first, first + size).
struct CellWeights {
  int first = 0;
  std::vector<double> w;
};

CellWeights cellWeights(double sigma, int scale, int reach) {
  CellWeights k;
  k.first = -reach * scale;
  const int last = (reach + 1) * scale - 1;
  // Fine cell d spans [d/scale - 1/2, (d+1)/scale - 1/2] in pixels from the pixel's centre; the
  // weight is the integral of K(-y) over it, C(1/2 - d/scale) - C(1/2 - (d+1)/scale).
  for (int d = k.first; d <= last; ++d)
    k.w.push_back(lensStepProfile(0.5 - static_cast<double>(d) / scale, sigma) -
                  lensStepProfile(0.5 - static_cast<double>(d + 1) / scale, sigma));
  return k;
}

}  // namespace

double lensStepProfile(double u, double sigma) {
  const auto g = [](double x) { return x * normalCdf(x) + normalPdf(x); };
  return sigma * (g((u + 0.5) / sigma) - g((u - 0.5) / sigma));
}

cv::Mat renderLensBlurred(const std::vector<Primitive>& primitives, const SceneSpec& spec) {
  const int s = spec.lensSupersampling;
  // The sub-scanlines place an edge along y to half their spacing, so a horizontal edge sits up to
  // 1/(2 * 2048) px off with 256 per fine row at scale 8: finer than spec.subrows, which is meant
  // for the pixel-grid model.
  const int subrows = std::max(kLensSubrows, (spec.subrows + s - 1) / s);
  const int reach = static_cast<int>(std::ceil(0.5 + 6.0 * spec.blurSigma));  // pixels
  const CellWeights k = cellWeights(spec.blurSigma, s, reach);
  const int n = static_cast<int>(k.w.size());
  const int width = spec.size.width, height = spec.size.height;
  cv::Mat out(spec.size, CV_64F);
  constexpr int kBand = 16;  // output rows per band
  std::vector<double> rowOut(static_cast<size_t>(width));
  cv::Mat fine, across;  // reused by every band
  for (int j0 = 0; j0 < height; j0 += kBand) {
    const int j1 = std::min(height, j0 + kBand);
    // Fine rows and columns every output pixel of the band reads.
    const cv::Rect window((0 - reach) * s, (j0 - reach) * s, (width + 2 * reach) * s,
                          (j1 - j0 + 2 * reach) * s);
    paintCoverageInto(primitives, window, spec.background, s, subrows, fine);
    // Along x: H(r, i) = sum_d w[d] F(r, i s + d). By parts, with C_d the cumulative weights
    // (1 left of the kernel, 0 right of it): H = F(first) + sum_d C_d (F(d) - F(d - 1)), and
    // the differences vanish except at edges, so each row costs its length plus its edges.
    std::vector<double> tail(static_cast<size_t>(n) + 1, 0.0);  // tail[d] = sum_{e >= d} w[e]
    for (int d = n - 1; d >= 0; --d) tail[d] = tail[d + 1] + k.w[d];
    across.create(fine.rows, width, CV_64F);
    for (int r = 0; r < fine.rows; ++r) {
      const double* f = fine.ptr<double>(r);
      double* h = across.ptr<double>(r);
      // Fine column of pixel i's cell d: (i + reach) * s + d relative to the window.
      for (int i = 0; i < width; ++i) h[i] = f[(i + reach) * s + k.first];
      for (int m = 1; m < fine.cols; ++m) {
        const double step = f[m] - f[m - 1];
        if (step == 0.0) continue;
        // Pixels i with d = m - (i + reach) s in (first, first + n): weight tail[d - first].
        const int iLow = std::max(0, (m - k.first - n) / s - reach - 1);
        const int iHigh = std::min(width - 1, (m - k.first) / s - reach + 1);
        for (int i = iLow; i <= iHigh; ++i) {
          const int d = m - (i + reach) * s - k.first;
          if (d > 0 && d < n) h[i] += step * tail[static_cast<size_t>(d)];
        }
      }
    }
    // Along y: dense, on the band's few output rows.
    for (int j = j0; j < j1; ++j) {
      std::fill(rowOut.begin(), rowOut.end(), 0.0);
      const int r0 = (j - j0 + reach) * s + k.first;  // fine row of d = first
      for (int d = 0; d < n; ++d) {
        const double w = k.w[static_cast<size_t>(d)];
        const double* h = across.ptr<double>(r0 + d);
        for (int i = 0; i < width; ++i) rowOut[i] += w * h[i];
      }
      std::copy(rowOut.begin(), rowOut.end(), out.ptr<double>(j));
    }
  }
  return out;
}

}  // namespace facet::scene
