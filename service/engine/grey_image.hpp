#pragma once
// Frames and reference images as one grey channel (the algorithms measure on grey values).

#include <opencv2/core.hpp>

namespace facet::service {

// BGR or BGRA to grey; a one-channel image is returned as it is (no copy).
cv::Mat toGrey(const cv::Mat& image);

}  // namespace facet::service
