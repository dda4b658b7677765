#pragma once
// How much more blurred one of two registered views is than the other. Two photographs of a
// scene differ by more than their sampling when focus or depth of field differ between them (a
// refocused lens, a part nearer or farther than the focus plane). Correlating a sharp patch with a
// blurred one locates the pair worse than correlating two equally blurred ones (the matched filter
// for a blurred patch is the blurred patch): on Oxford bikes 1-6 the re-matched pairs lay a
// median 1.5 px from the best homography, and their fit 1.7 px from the dense reference.

#include <opencv2/core.hpp>

namespace facet {

// How much fine detail `grey` holds where `mask` is set: its mean squared gradient over its
// variance there (1/px^2). A change of contrast or exposure leaves it unchanged; a Gaussian blur
// lowers it, monotonically in the blur's width.
double detailOf(const cv::Mat& grey, const cv::Mat& mask);

// The Gaussian blur (sigma, pixels) that brings the sharper of `a` and `b` (the same view of one
// scene, e.g. a reference warped onto an image, CV_32F) to the other's detail over `mask` (CV_8U,
// where both hold the scene): positive when `a` is the sharper, negative when `b` is, 0 where
// they hold the same detail within a tenth (sampling and noise) or the overlap is too small
// (< 1000 pixels 8 px inside the mask). At most 6 px either way.
double relativeDefocus(const cv::Mat& a, const cv::Mat& b, const cv::Mat& mask);

}  // namespace facet
