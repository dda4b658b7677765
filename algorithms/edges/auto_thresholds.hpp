#pragma once
// Automatic Canny thresholds from the gradient-magnitude histogram of a region.
//
// Method: the magnitudes inside the region form two populations, flat or noisy background (the
// large majority) and edges. Otsu's criterion on the histogram of magnitudes (256 bins from 0 to
// the region's maximum) gives the threshold that best separates the two; that is `high`. Noise
// must never pass it: with the noise level estimated from the median magnitude (background
// pixels dominate every region, and for Gaussian image noise the gradient magnitude is Rayleigh
// distributed, median = 1.18 sigma_g), `high` is at least 4 sigma_g. `low` = lowRatio * high
// (Canny's recommendation is 1/2 to 1/3), so weak parts of an edge survive when connected to
// strong ones. Both scale with the image contrast.

#include <opencv2/core.hpp>

namespace facet {

struct AutoThresholdParams {
  double lowRatio = 0.4;     // low = lowRatio * high
  double minHigh = 2.0;      // grey levels per pixel: floor for featureless regions
  double noiseFactor = 4.0;  // high >= noiseFactor * (median magnitude / 1.18)
};

struct CannyThresholds {
  double low = 0;  // grey levels per pixel
  double high = 0;
};

// `magnitude`: CV_32F gradient magnitude (grey levels per pixel); `mask`: CV_8U of the same size
// or empty (= every pixel).
CannyThresholds autoCannyThresholds(const cv::Mat& magnitude, const cv::Mat& mask = {},
                                    const AutoThresholdParams& params = {});

}  // namespace facet
