#pragma once
// The one conversion of a camera or file image to grey that every path shares (inspection,
// training, the command-line tools, registration): colour (BGR or BGRA, as OpenCV reads it)
// becomes one channel by the ITU-R BT.601 luma weights; the depth (8 or 16 bit, float) stays.

#include <opencv2/core.hpp>

namespace facet {

// `image` itself when it already has one channel (no copy); a new grey image otherwise.
[[nodiscard]] cv::Mat toGrey(const cv::Mat& image);

}  // namespace facet
