#include "tests/hardening/bad_image_files.hpp"

#include <zlib.h>

#include <vector>

#include <opencv2/imgcodecs.hpp>

namespace facet::test {
namespace {

std::string bigEndian32(std::uint32_t v) {
  return {static_cast<char>(v >> 24), static_cast<char>(v >> 16), static_cast<char>(v >> 8),
          static_cast<char>(v)};
}

}  // namespace

std::string encodeImage(const std::string& ext, const cv::Mat& image) {
  std::vector<std::uint8_t> bytes;
  cv::imencode(ext, image, bytes);
  return {bytes.begin(), bytes.end()};
}

std::string pngChunk(const std::string& type, const std::string& data) {
  const std::string body = type + data;
  const auto crc = static_cast<std::uint32_t>(
      ::crc32(0, reinterpret_cast<const Bytef*>(body.data()), static_cast<uInt>(body.size())));
  return bigEndian32(static_cast<std::uint32_t>(data.size())) + body + bigEndian32(crc);
}

std::string pngHeaderOnly(std::uint32_t width, std::uint32_t height, char depth, char colour) {
  std::string ihdr = bigEndian32(width) + bigEndian32(height);
  ihdr += std::string{depth, colour, 0, 0, 0};
  const std::string idat = "\x78\x9c\x63\x00\x00\x00\x01\x00\x01";  // zlib of one zero byte
  return std::string("\x89PNG\r\n\x1a\n", 8) + pngChunk("IHDR", ihdr) + pngChunk("IDAT", idat) +
         pngChunk("IEND", "");
}

}  // namespace facet::test
