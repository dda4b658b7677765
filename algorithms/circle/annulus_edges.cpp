#include "algorithms/circle/annulus_edges.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

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

  // Annulus pixels that carry a full 5x5 window inside the image (and inside the crop).
  cv::Mat mask = cv::Mat::zeros(crop.size(), CV_8U);
  const int xLo = std::max(2, crop.x + 2), xHi = std::min(image.cols - 3, crop.br().x - 3);
  const int yLo = std::max(2, crop.y + 2), yHi = std::min(image.rows - 3, crop.br().y - 3);
  const double scale = image.depth() == CV_16U ? 1.0 / 256.0 : 1.0;
  const int sectors = std::clamp(static_cast<int>(2.0 * std::numbers::pi * rOut / 6.0), 8, 120);
  const EdgeGradient gradient = computeEdgeGradient(image, crop);
  std::vector<float> noise, peak(sectors, 0.0f);
  for (int y = yLo; y <= yHi; ++y) {
    const double dy = y - centre.y;
    if (std::abs(dy) > rOut) continue;
    const double outer = std::sqrt(rOut * rOut - dy * dy);
    const double inner = std::abs(dy) < rIn ? std::sqrt(rIn * rIn - dy * dy) : -1.0;
    auto* row = mask.ptr<std::uint8_t>(y - crop.y);
    const float* magnitude = gradient.magnitude.ptr<float>(y - crop.y) - crop.x;
    const int xa = std::max(xLo, static_cast<int>(std::ceil(centre.x - outer)));
    const int xb = std::min(xHi, static_cast<int>(std::floor(centre.x + outer)));
    for (int x = xa; x <= xb; ++x) {
      const double dx = x - centre.x;
      if (std::abs(dx) < inner) continue;
      row[x - crop.x] = 255;
      ++out.annulusPixels;
      // Sector from the "diamond angle" in [0, 4), a monotonic stand-in for atan2.
      const double q = dy / (std::abs(dx) + std::abs(dy) + 1e-12);
      const double turn = (dx < 0.0 ? 2.0 - q : (dy < 0.0 ? 4.0 + q : q)) / 4.0;
      float& sectorPeak = peak[std::min(sectors - 1, static_cast<int>(turn * sectors))];
      sectorPeak = std::max(sectorPeak, magnitude[x]);
      // Immerkaer's noise mask (its taps' squares sum to 36), on every third pixel: plenty for
      // a median.
      if ((x + y) % 3 != 0) continue;
      auto at = [&](int u, int v) {
        return image.depth() == CV_16U ? image.at<std::uint16_t>(v, u) * scale
                                       : static_cast<double>(image.at<std::uint8_t>(v, u));
      };
      const double n = at(x - 1, y - 1) - 2 * at(x, y - 1) + at(x + 1, y - 1) - 2 * at(x - 1, y) +
                       4 * at(x, y) - 2 * at(x + 1, y) + at(x - 1, y + 1) - 2 * at(x, y + 1) +
                       at(x + 1, y + 1);
      noise.push_back(static_cast<float>(std::abs(n)));
    }
  }
  if (out.annulusPixels == 0) return out;

  out.noiseSigma = median(noise) / (0.6745 * 6.0);
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

  const cv::Mat edges = cannyFromGradient(gradient, out.lowThreshold, out.highThreshold, mask);
  for (int y = 0; y < edges.rows; ++y) {
    const auto* e = edges.ptr<std::uint8_t>(y);
    for (int x = 0; x < edges.cols; ++x)
      if (e[x])
        if (auto point = facetEdgePoint(image, cv::Point(x + crop.x, y + crop.y)))
          out.points.push_back(*point);
  }
  return out;
}

}  // namespace facet
