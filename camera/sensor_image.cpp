#include "camera/sensor_image.hpp"

#include <opencv2/imgproc.hpp>

namespace facet {
namespace {

// OpenCV names Bayer patterns by the second row's first two pixels; GenICam by the first row's.
// So GenICam BayerRG (R G / G B) is OpenCV's BayerBG code, and so on.
int bayerToBgr(SensorLayout layout) {
  switch (layout) {
    case SensorLayout::BayerRG8:
      return cv::COLOR_BayerBG2BGR;
    case SensorLayout::BayerGR8:
      return cv::COLOR_BayerGB2BGR;
    case SensorLayout::BayerGB8:
      return cv::COLOR_BayerGR2BGR;
    default:
      return cv::COLOR_BayerRG2BGR;  // BayerBG8
  }
}

int bayerToGrey(SensorLayout layout) {
  switch (layout) {
    case SensorLayout::BayerRG8:
      return cv::COLOR_BayerBG2GRAY;
    case SensorLayout::BayerGR8:
      return cv::COLOR_BayerGB2GRAY;
    case SensorLayout::BayerGB8:
      return cv::COLOR_BayerGR2GRAY;
    default:
      return cv::COLOR_BayerRG2GRAY;
  }
}

// 16-bit grey cannot become Bgr8 without losing its low byte; keep the high byte.
cv::Mat mono16ToBgr8(const cv::Mat& view) {
  cv::Mat grey8;
  view.convertTo(grey8, CV_8U, 1.0 / 256.0);
  cv::cvtColor(grey8, grey8, cv::COLOR_GRAY2BGR);
  return grey8;
}

}  // namespace

cv::Mat convertSensorImage(const cv::Mat& view, SensorLayout layout, ColourConversion colour,
                           PixelFormat& format) {
  cv::Mat out;
  const bool mono = colour == ColourConversion::Mono;
  const bool to_colour = colour == ColourConversion::Colour;
  switch (layout) {
    case SensorLayout::Mono8:
      if (to_colour) {
        cv::cvtColor(view, out, cv::COLOR_GRAY2BGR);
        format = PixelFormat::Bgr8;
      } else {
        out = view.clone();
        format = PixelFormat::Mono8;
      }
      break;
    case SensorLayout::Mono16:
      if (to_colour) {
        out = mono16ToBgr8(view);
        format = PixelFormat::Bgr8;
      } else {
        out = view.clone();
        format = PixelFormat::Mono16;
      }
      break;
    case SensorLayout::Rgb8:
    case SensorLayout::Bgr8: {
      const bool rgb = layout == SensorLayout::Rgb8;
      if (mono) {
        cv::cvtColor(view, out, rgb ? cv::COLOR_RGB2GRAY : cv::COLOR_BGR2GRAY);
        format = PixelFormat::Mono8;
      } else {
        if (rgb)
          cv::cvtColor(view, out, cv::COLOR_RGB2BGR);
        else
          out = view.clone();
        format = PixelFormat::Bgr8;
      }
      break;
    }
    case SensorLayout::BayerRG8:
    case SensorLayout::BayerGR8:
    case SensorLayout::BayerGB8:
    case SensorLayout::BayerBG8:
      cv::cvtColor(view, out, mono ? bayerToGrey(layout) : bayerToBgr(layout));
      format = mono ? PixelFormat::Mono8 : PixelFormat::Bgr8;
      break;
    case SensorLayout::Yuyv:
      // YUYV to grey is the luma plane: one pass either way.
      cv::cvtColor(view, out, mono ? cv::COLOR_YUV2GRAY_YUYV : cv::COLOR_YUV2BGR_YUYV);
      format = mono ? PixelFormat::Mono8 : PixelFormat::Bgr8;
      break;
  }
  return out;
}

void applyColourConversion(cv::Mat& image, PixelFormat& format, ColourConversion colour) {
  if (colour == ColourConversion::Mono && format == PixelFormat::Bgr8) {
    cv::cvtColor(image, image, cv::COLOR_BGR2GRAY);
    format = PixelFormat::Mono8;
  } else if (colour == ColourConversion::Colour && format == PixelFormat::Mono8) {
    cv::cvtColor(image, image, cv::COLOR_GRAY2BGR);
    format = PixelFormat::Bgr8;
  } else if (colour == ColourConversion::Colour && format == PixelFormat::Mono16) {
    image = mono16ToBgr8(image);
    format = PixelFormat::Bgr8;
  }
}

}  // namespace facet
