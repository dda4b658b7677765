#pragma once
// Grey-value images on the 8-bit scale and their Sobel gradients, as used by both the model's
// training and the search (internal to facet_shape).

#include <opencv2/core.hpp>

namespace facet::shape_detail {

// 8-bit or 16-bit single-channel image -> CV_32F on the 8-bit grey scale (16-bit divided by 256).
cv::Mat toGreyFloat(const cv::Mat& image);

// Sobel derivatives of a CV_32F image in grey levels per pixel (3x3 Sobel divided by 8).
void sobelGradients(const cv::Mat& image, cv::Mat& gx, cv::Mat& gy);

}  // namespace facet::shape_detail
