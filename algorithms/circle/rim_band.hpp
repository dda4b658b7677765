#pragma once
// The rim band's pixels, as the grey-value circle fit (circle_profile_fit.cpp) samples them, and
// the screens that keep pixels of foreign objects (clutter, occluders) out of that fit.

#include <cstdint>
#include <span>
#include <vector>

#include <opencv2/core.hpp>

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

double medianOf(std::vector<double> v);

// Robust sigma (1.4826 x median absolute value) of residuals around zero.
double robustSigma(std::span<const double> residuals);

// Angular bins whose grey residuals are too large for the noise (1 = contaminated).
std::vector<std::uint8_t> contaminatedBins(const std::vector<Sample>& samples,
                                           std::span<const double> residuals, int bins);

// Removes the samples whose pixel, or a neighbour among the samples, has a grey-value gradient
// the blurred rim around `centre` with `radius` cannot explain. `box` holds every sample's pixel.
void dropForeignGradients(std::vector<Sample>& samples, const cv::Mat& image, cv::Point2d centre,
                          double radius, double noiseSigma, cv::Rect box);

}  // namespace facet::rim_band
