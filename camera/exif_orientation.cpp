#include "camera/exif_orientation.hpp"

#include <cstdint>
#include <cstring>

#include <opencv2/core.hpp>

namespace facet {
namespace {

constexpr std::uint16_t kOrientationTag = 274;
constexpr std::uint16_t kShort = 3;
constexpr std::size_t kEntryBytes = 12;

// The TIFF structure after "Exif\0\0", in its own byte order; every read is bounds-checked.
class TiffBytes {
 public:
  TiffBytes(const unsigned char* data, std::size_t size, bool bigEndian)
      : data_(data), size_(size), big_(bigEndian) {}
  std::optional<std::uint16_t> u16(std::size_t at) const {
    if (at > size_ || size_ - at < 2) return std::nullopt;
    const unsigned a = data_[at], b = data_[at + 1];
    return static_cast<std::uint16_t>(big_ ? (a << 8) | b : (b << 8) | a);
  }
  std::optional<std::uint32_t> u32(std::size_t at) const {
    const auto hi = u16(big_ ? at : at + 2), lo = u16(big_ ? at + 2 : at);
    if (!hi || !lo) return std::nullopt;
    return (std::uint32_t{*hi} << 16) | *lo;
  }

 private:
  const unsigned char* data_;
  std::size_t size_;
  bool big_;
};

}  // namespace

std::optional<int> exifOrientation(const unsigned char* block, std::size_t size) {
  if (size < 6 + 8 || std::memcmp(block, "Exif\0\0", 6) != 0) return std::nullopt;
  const unsigned char* tiff = block + 6;
  const std::size_t bytes = size - 6;
  const bool big = tiff[0] == 'M' && tiff[1] == 'M';
  if (!big && !(tiff[0] == 'I' && tiff[1] == 'I')) return std::nullopt;
  const TiffBytes t(tiff, bytes, big);
  const auto mark = t.u16(2);
  const auto directory = t.u32(4);
  if (!mark || *mark != 42 || !directory) return std::nullopt;
  const auto entries = t.u16(*directory);
  if (!entries) return std::nullopt;
  std::optional<int> orientation;
  for (std::size_t i = 0; i < *entries; ++i) {
    const std::size_t at = std::size_t{*directory} + 2 + i * kEntryBytes;
    const auto tag = t.u16(at), type = t.u16(at + 2);
    const auto count = t.u32(at + 4);
    const auto value = t.u16(at + 8);
    if (!tag || !type || !count || !value) return std::nullopt;  // the directory is cut short
    if (*tag != kOrientationTag) continue;
    if (orientation || *type != kShort || *count != 1 || *value < 1 || *value > 8)
      return std::nullopt;
    orientation = *value;
  }
  return orientation.value_or(1);
}

void applyExifOrientation(cv::Mat& image, int orientation) {
  // Exif's numbering: where the stored first row and first column are seen. Orientations 5-8
  // have rows and columns exchanged: a transpose, then the flip that 1-4 would need.
  if (orientation >= 5 && orientation <= 8) cv::transpose(image, image);
  switch (orientation) {
    case 2:  // first row at the top, first column on the right
    case 6:
      cv::flip(image, image, 1);
      break;
    case 3:  // first row at the bottom, first column on the right
    case 7:
      cv::flip(image, image, -1);
      break;
    case 4:  // first row at the bottom, first column on the left
    case 8:
      cv::flip(image, image, 0);
      break;
    default:  // 1 and 5: nothing more
      break;
  }
}

}  // namespace facet
