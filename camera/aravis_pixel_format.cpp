#include "camera/aravis_pixel_format.hpp"

#include <algorithm>
#include <iterator>

#include <opencv2/core.hpp>

namespace facet {

std::optional<SensorLayout> layoutOf(ArvPixelFormat format) {
  switch (format) {
    case ARV_PIXEL_FORMAT_MONO_8:
      return SensorLayout::Mono8;
    case ARV_PIXEL_FORMAT_MONO_16:
      return SensorLayout::Mono16;
    case ARV_PIXEL_FORMAT_RGB_8_PACKED:
      return SensorLayout::Rgb8;
    case ARV_PIXEL_FORMAT_BGR_8_PACKED:
      return SensorLayout::Bgr8;
    case ARV_PIXEL_FORMAT_BAYER_RG_8:
      return SensorLayout::BayerRG8;
    case ARV_PIXEL_FORMAT_BAYER_GR_8:
      return SensorLayout::BayerGR8;
    case ARV_PIXEL_FORMAT_BAYER_GB_8:
      return SensorLayout::BayerGB8;
    case ARV_PIXEL_FORMAT_BAYER_BG_8:
      return SensorLayout::BayerBG8;
    default:
      return std::nullopt;
  }
}

int cvTypeOf(SensorLayout layout) {
  switch (layout) {
    case SensorLayout::Mono16:
      return CV_16UC1;
    case SensorLayout::Rgb8:
    case SensorLayout::Bgr8:
      return CV_8UC3;
    case SensorLayout::Yuyv:
      return CV_8UC2;
    default:
      return CV_8UC1;
  }
}

bool supportedPixelFormatName(const std::string& name) {
  static const char* names[] = {"Mono8",    "Mono16",   "RGB8",     "BGR8",
                                "BayerRG8", "BayerGR8", "BayerGB8", "BayerBG8"};
  return std::find(std::begin(names), std::end(names), name) != std::end(names);
}

}  // namespace facet
