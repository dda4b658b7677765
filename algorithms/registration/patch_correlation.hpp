// Normalised cross-correlation of a small patch over a small search window, by direct sums.
#pragma once

#include <opencv2/core.hpp>

namespace facet {

// result(y, x) = the correlation coefficient of `patch` with the window of `image` whose top-left
// corner is (x, y), as cv::matchTemplate's TM_CCOEFF_NORMED defines it: (image.rows - patch.rows +
// 1) x (image.cols - patch.cols + 1), CV_32F. Both inputs CV_32F, one channel. A flat patch or
// window gives 0.
// Why not cv::matchTemplate: it correlates through the DFT, which pays off for large templates;
// the re-matching of a registration correlates thousands of 15x15 patches over 17x17 or 7x7
// shifts, where direct sums take a fraction of its time.
void correlatePatch(const cv::Mat& image, const cv::Mat& patch, cv::Mat& result);

}  // namespace facet
