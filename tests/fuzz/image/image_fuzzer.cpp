// libFuzzer target: the replay backend's image decoders: the one inside the image-codec module
// (camera/image_file_decoder.hpp: OpenImageIO and, for 16-bit PNM, OpenCV) and the plain-PNG
// plain-JPEG, plain-TIFF, plain-BMP and binary-PGM readers that run in the process before it
// (camera/png_file.hpp, camera/jpeg_file.hpp, camera/tiff_file.hpp, camera/bmp_file.hpp,
// camera/pgm_file.hpp). The first
// byte picks the file extension the replay folder accepts, the rest is the file. Expected outcome
// for bad input: an error naming the file (module) or no image (plain readers: the module then
// decides). An image that reads must have the size its header announced and a frame format; where
// both read a file, they agree on its size.
//
// The pixel limit is lower than the camera's default (2^28) so that runs stay within the
// fuzzer's memory limit; the header check in front of any allocation is the same code.

#include <array>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>

#include <opencv2/core.hpp>

#include "camera/bmp_file.hpp"
#include "camera/decoded_frame.hpp"
#include "camera/image_file_decoder.hpp"
#include "camera/jpeg_file.hpp"
#include "camera/pgm_file.hpp"
#include "camera/png_file.hpp"
#include "camera/tiff_file.hpp"
#include "tests/fuzz/fuzz_input_file.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const facet::fuzz::FuzzInputFolder folder;
  static const std::array<const char*, 8> kExtensions = {".png", ".tif", ".bmp", ".pgm",
                                                         ".ppm", ".pbm", ".jpg", ".txt"};
  if (size == 0) return 0;
  const std::string name = std::string("frame") + kExtensions[data[0] % kExtensions.size()];
  const auto file = folder.write(name, data + 1, size - 1);
  constexpr std::uint64_t kMaxPixels = std::uint64_t{1} << 22;
  const facet::ImageFileContent content = facet::decodeImageFile(file, kMaxPixels);
  if (content.ok()) {
    if (content.image.empty() || content.image.total() > kMaxPixels) std::abort();
  } else if (!content.image.empty() || content.error.find(file.string()) != 0) {
    std::abort();  // a refused file leaves no pixels and its message names it
  }
  if (const auto plain = facet::readPlainPng(file, kMaxPixels)) {
    const cv::Mat& p = plain->pixels;
    if (p.empty() || p.total() > kMaxPixels || p.channels() < 1 || p.channels() > 4 ||
        (p.depth() != CV_8U && p.depth() != CV_16U))
      std::abort();
    if (content.ok() && content.image.size() != p.size()) std::abort();
  }
  for (const auto output : {facet::JpegOutput::Stored, facet::JpegOutput::Grey}) {
    if (const auto plain = facet::readPlainJpeg(file, kMaxPixels, output)) {
      const cv::Mat& p = plain->pixels;
      if (p.empty() || p.total() > kMaxPixels || p.depth() != CV_8U ||
          (p.channels() != 1 && p.channels() != 3) ||
          (output == facet::JpegOutput::Grey && p.channels() != 1))
        std::abort();
      if (content.ok() && content.image.size() != p.size()) std::abort();
    }
  }
  if (const auto plain = facet::readPlainTiff(file, kMaxPixels)) {
    const cv::Mat& p = *plain;
    if (p.empty() || p.total() > kMaxPixels || (p.depth() != CV_8U && p.depth() != CV_16U) ||
        (p.channels() != 1 && p.channels() != 3))
      std::abort();
    if (content.ok() && content.image.size() != p.size()) std::abort();
  }
  if (const auto plain = facet::readPlainBmp(file, kMaxPixels)) {
    const cv::Mat& p = *plain;
    if (p.empty() || p.total() > kMaxPixels || p.depth() != CV_8U ||
        (p.channels() != 1 && p.channels() != 3))
      std::abort();
    // Where the module reads it too, to the same size.
    if (content.ok() && content.image.size() != p.size()) std::abort();
  }
  if (const auto plain = facet::readBinaryPgm(file, kMaxPixels)) {
    const cv::Mat& p = *plain;
    if (p.empty() || p.total() > kMaxPixels || p.channels() != 1 ||
        (p.depth() != CV_8U && p.depth() != CV_16U))
      std::abort();
    // The module takes PNM samples from OpenCV's reader, which this one matches sample for sample.
    if (content.ok() &&
        (content.image.size() != p.size() ||
         cv::norm(content.image, facet::frameOfDecodedPixels(p).image, cv::NORM_INF) != 0))
      std::abort();
  }
  return 0;
}
