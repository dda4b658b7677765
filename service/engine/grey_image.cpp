#include "service/engine/grey_image.hpp"

#include <opencv2/imgproc.hpp>

namespace facet::service {

cv::Mat toGrey(const cv::Mat& image) {
  if (image.channels() == 1) return image;
  cv::Mat grey;
  cv::cvtColor(image, grey, image.channels() == 4 ? cv::COLOR_BGRA2GRAY : cv::COLOR_BGR2GRAY);
  return grey;
}

}  // namespace facet::service
