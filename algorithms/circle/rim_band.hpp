#pragma once
// The rim band's pixels, as the grey-value circle fit (circle_profile_fit.cpp) samples them, and
// the screens that keep pixels of foreign objects (clutter, occluders) out of that fit.

#include <cstdint>
#include <span>
#include <vector>

#include <opencv2/core.hpp>

#include "algorithms/edges/subpixel_edges.hpp"

namespace facet::rim_band {

// One pixel of the band, relative to the starting centre.
struct Sample {
  double x, y, grey;
  int bin;          // angular bin
  int column, row;  // the pixel
};

// Grey value of pixel (x, y) on the 8-bit scale (16-bit images divided by 256), the scale of the
// noise level and of the model.
// Inline: called for every pixel of the band.
inline double greyAt(const cv::Mat& image, int x, int y) {
  return image.depth() == CV_16U ? image.at<std::uint16_t>(y, x) / 256.0
                                 : static_cast<double>(image.at<std::uint8_t>(y, x));
}

// The share of the pixels of the annulus rIn <= |p - centre| <= rOut (inside the image) at the
// sensor's limits; 0 when the annulus holds no pixel.
double clippedShare(const cv::Mat& image, cv::Point2d centre, double rIn, double rOut);

// The median of v (the value of rank size / 2, as std::nth_element places it; 0 when empty). Of
// two zeros of either sign, either may come back.
double medianOf(std::vector<double> v);

// How many band pixels a clean rim's grey-value fit needs for a centre precision of about
// 0.0035 px per axis by the Cramer-Rao bound, at contrast-to-noise `snr` in a band `halfWidth` px
// either side of the rim (information per band pixel about snr^2 / (2 sqrt(pi) s) / (4 halfWidth)
// at blur s about 1); never below 1000. A big rim keeps that many and no more: it bounds the time
// of big, high-contrast circles and keeps every pixel of faint ones.
double pixelsNeeded(double snr, double halfWidth);

// The angular bins of a rim that take part in a grey-value fit, from `covered` (1: an inlier edge
// point lies in the bin): gaps of up to 2 bins closed (edge points missed in noise), then `margin`
// bins dropped at each end of every covered run (next to an occluder or a clutter blob the band
// mixes in foreign edges).
std::vector<std::uint8_t> closedCoverage(const std::vector<std::uint8_t>& covered, int margin);

// The pixels of a box that a grey-value fit leaves out because a foreign edge point (clutter, an
// occluder's border) is near: within 2 px, and farther for a strong edge, as far as its blurred
// step still changes the grey by more than a quarter of the noise (`noiseSigma`, grey levels;
// 0 = unknown: half a grey level).
class ForeignReach {
 public:
  ForeignReach(const std::vector<EdgePoint>& foreign, double noiseSigma, cv::Rect box);
  // The marks of image row y, indexed by image column (1 = out), or nullptr when no pixel of
  // the row is near a foreign edge (most rows).
  [[nodiscard]] const std::uint8_t* row(int y) const {
    return marked_.empty() || !marked_[static_cast<std::size_t>(y - box_.y)]
               ? nullptr
               : map_.ptr<std::uint8_t>(y - box_.y) - box_.x;
  }

 private:
  cv::Rect box_;
  cv::Mat map_;
  // 1: the row of map_ is zeroed and marked. A row is zeroed when an edge first reaches it:
  // zeroing the whole map cost more than marking it.
  std::vector<std::uint8_t> marked_;
};

// Robust sigma (1.4826 x median absolute value) of residuals around zero.
double robustSigma(std::span<const double> residuals);

// Angular bins whose grey residuals are too large for the noise (1 = contaminated).
std::vector<std::uint8_t> contaminatedBins(const std::vector<Sample>& samples,
                                           std::span<const double> residuals, int bins);

// Removes the samples whose pixel, or a neighbour among the samples, has a grey-value gradient
// the blurred rim cannot explain. The rim near each sample is judged from its offset (x, y): the
// rim's normal there is along it, and the sample lies |(x, y)| - radius pixels outside the rim
// (a circle's band: the offsets from its centre). `box` holds every sample's pixel.
void dropForeignGradients(std::vector<Sample>& samples, const cv::Mat& image, double radius,
                          double noiseSigma, cv::Rect box);

}  // namespace facet::rim_band
