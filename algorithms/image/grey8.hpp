#pragma once
// Eight bits for the OpenCV functions that take nothing else (the chessboard and circle-grid
// detectors): a 16-bit image scaled by 1/256; an 8-bit one is returned as it is (no copy).

#include <opencv2/core.hpp>

namespace facet {

inline cv::Mat toGrey8(const cv::Mat& image) {
  if (image.depth() == CV_8U) return image;
  cv::Mat out;
  image.convertTo(out, CV_8U, 1.0 / 256.0);
  return out;
}

}  // namespace facet
