#pragma once
// What the image-codec module makes of a file: the reference the in-process readers
// (camera/png_file.hpp, jpeg_file.hpp, tiff_file.hpp) must meet, computed here without them.

#include <filesystem>
#include <fstream>
#include <iterator>
#include <vector>

#include <OpenImageIO/imageio.h>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "camera/decoded_frame.hpp"
#include "camera/image_codecs.hpp"

namespace facet::test {

inline std::vector<char> fileBytes(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), {}};
}

// cv::imdecode in the module (readImage's reference): the file's bytes, so that no in-process
// reader can stand in for it.
inline cv::Mat moduleRead(const std::filesystem::path& file, int flags) {
  std::vector<char> b = fileBytes(file);
  return decodeImage(cv::Mat(1, static_cast<int>(b.size()), CV_8UC1, b.data()), flags);
}

// The module's replay reader (camera/image_file_decoder.cpp, readImageFile's reference):
// OpenImageIO reads the stored channels at 8 or 16 bits, colour in RGB order, and the frame rule
// follows.
inline cv::Mat moduleFrame(const std::filesystem::path& file) {
  namespace OIIO = OIIO_NAMESPACE;
  auto input = OIIO::ImageInput::open(file.string());
  if (!input) return {};
  const OIIO::ImageSpec& spec = input->spec();
  const bool eight = spec.format.size() == 1;
  const int channels = spec.nchannels >= 3 ? 3 : 1;
  cv::Mat image(spec.height, spec.width, CV_MAKETYPE(eight ? CV_8U : CV_16U, channels));
  if (!input->read_image(0, 0, 0, channels, eight ? OIIO::TypeDesc::UINT8 : OIIO::TypeDesc::UINT16,
                         image.data))
    return {};
  if (channels == 3) cv::cvtColor(image, image, cv::COLOR_RGB2BGR);
  return frameOfDecodedPixels(std::move(image)).image;
}

}  // namespace facet::test
