#pragma once
// Turning a view of a driver's buffer into the pixels of a Frame in one pass: the single copy
// that grabbing is allowed (a demosaic, colour conversion or decode *is* that copy).

#include <opencv2/core/mat.hpp>

#include "camera/camera.hpp"
#include "camera/camera_settings.hpp"

namespace facet {

// Pixel layouts that drivers hand us.
enum class SensorLayout {
  Mono8,     // CV_8UC1 view
  Mono16,    // CV_16UC1 view
  Rgb8,      // CV_8UC3 view, R first (GenICam RGB8)
  Bgr8,      // CV_8UC3 view, B first
  BayerRG8,  // CV_8UC1 view of a colour-filter mosaic, GenICam naming (first row R G R G ...)
  BayerGR8,
  BayerGB8,
  BayerBG8,
  Yuyv,  // CV_8UC2 view, YUV 4:2:2 (V4L2 YUYV)
};

// Converts `view` (not owned; may be the driver's memory) into a freshly allocated image with
// exactly one pass over the pixels, and sets `format` to what the result holds.
cv::Mat convertSensorImage(const cv::Mat& view, SensorLayout layout, ColourConversion colour,
                           PixelFormat& format);

// Applies `colour` to an image the frame already owns (replay), in place where possible.
void applyColourConversion(cv::Mat& image, PixelFormat& format, ColourConversion colour);

}  // namespace facet
