#include "algorithms/shape/image_gradients.hpp"

#include <stdexcept>

#include <opencv2/imgproc.hpp>

namespace facet::shape_detail {

cv::Mat toGreyFloat(const cv::Mat& image) {
  if (image.channels() != 1 || (image.depth() != CV_8U && image.depth() != CV_16U))
    throw std::invalid_argument("expected an 8-bit or 16-bit single-channel image");
  cv::Mat grey;
  image.convertTo(grey, CV_32F, image.depth() == CV_16U ? 1.0 / 256.0 : 1.0);
  return grey;
}

void sobelGradients(const cv::Mat& image, cv::Mat& gx, cv::Mat& gy) {
  // The 3x3 Sobel kernel is 8 times the central difference of a [1 2 1]-smoothed image.
  cv::Sobel(image, gx, CV_32F, 1, 0, 3, 1.0 / 8.0, 0.0, cv::BORDER_REPLICATE);
  cv::Sobel(image, gy, CV_32F, 0, 1, 3, 1.0 / 8.0, 0.0, cv::BORDER_REPLICATE);
}

}  // namespace facet::shape_detail
