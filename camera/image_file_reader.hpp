#pragma once
// Reading one recorded image, safely: the header is checked against a pixel limit before any
// pixel memory is allocated, and a truncated or corrupt file is an error with its name, never a
// crash or a half-filled frame. Decoded by OpenImageIO in the image-codec module
// (image_codecs.hpp); a module that cannot be loaded is an error of the file's read, too.

#include <cstdint>
#include <filesystem>
#include <string>

#include <opencv2/core/mat.hpp>

#include "camera/camera.hpp"

namespace facet {

struct ImageFileContent {
  cv::Mat image;  // Mono8, Mono16 or Bgr8 (OpenCV channel order)
  PixelFormat format = PixelFormat::Mono8;
  std::string error;  // non-empty when the file could not be read; names the file
  bool ok() const { return error.empty(); }
};

// Reads `file`. 8-bit (and lower) files give 8-bit images, anything deeper gives 16 bits;
// grey(+alpha) gives one channel, colour(+alpha) gives BGR. Files announcing more than
// `max_pixels` (width * height) pixels are refused.
ImageFileContent readImageFile(const std::filesystem::path& file, std::uint64_t max_pixels);

}  // namespace facet
