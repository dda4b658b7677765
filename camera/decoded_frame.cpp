#include "camera/decoded_frame.hpp"

#include <opencv2/imgproc.hpp>

namespace facet {

ImageFileContent frameOfDecodedPixels(cv::Mat decoded) {
  ImageFileContent content;
  const bool deep = decoded.depth() == CV_16U;
  if (decoded.channels() <= 2) {
    if (decoded.channels() == 2) cv::extractChannel(decoded, decoded, 0);
    content.format = deep ? PixelFormat::Mono16 : PixelFormat::Mono8;
  } else {
    if (decoded.channels() == 4) cv::cvtColor(decoded, decoded, cv::COLOR_BGRA2BGR);
    if (deep) decoded.convertTo(decoded, CV_8U, 1.0 / 256.0);
    content.format = PixelFormat::Bgr8;
  }
  content.image = std::move(decoded);
  return content;
}

}  // namespace facet
