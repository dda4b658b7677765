#include "camera/bmp_file.hpp"

#include <array>
#include <cstring>
#include <fstream>
#include <iterator>
#include <vector>

namespace facet {
namespace {

constexpr std::size_t kFileHeader = 14;
constexpr std::uint32_t kInfoHeader = 40;  // BITMAPINFOHEADER; V4 (108) and V5 (124) extend it
constexpr std::uint32_t kBiRgb = 0;        // no compression
constexpr std::int64_t kMaxSide = 1 << 20;

std::uint32_t u32(const std::vector<unsigned char>& b, std::size_t at) {
  return std::uint32_t{b[at]} | std::uint32_t{b[at + 1]} << 8 | std::uint32_t{b[at + 2]} << 16 |
         std::uint32_t{b[at + 3]} << 24;
}
std::uint16_t u16(const std::vector<unsigned char>& b, std::size_t at) {
  return static_cast<std::uint16_t>(b[at] | b[at + 1] << 8);
}

}  // namespace

std::optional<cv::Mat> readPlainBmp(const std::filesystem::path& file, std::uint64_t maxPixels,
                                    const StoredLayoutFilter& wanted) {
  // The headers first: a file that is no plain BMP is not read further (the module reads it).
  std::ifstream in(file, std::ios::binary);
  std::vector<unsigned char> b(kFileHeader + kInfoHeader);
  if (!in.read(reinterpret_cast<char*>(b.data()), static_cast<std::streamsize>(b.size())) ||
      b[0] != 'B' || b[1] != 'M')
    return std::nullopt;

  const std::uint32_t pixelsAt = u32(b, 10);
  const std::uint32_t infoSize = u32(b, 14);
  if (infoSize != kInfoHeader && infoSize != 108 && infoSize != 124) return std::nullopt;
  const auto width = static_cast<std::int32_t>(u32(b, 18));
  const auto signedHeight = static_cast<std::int32_t>(u32(b, 22));
  const std::uint16_t planes = u16(b, 26), bits = u16(b, 28);
  const std::uint32_t compression = u32(b, 30), paletteUsed = u32(b, 46);
  if (planes != 1 || compression != kBiRgb || (bits != 8 && bits != 24)) return std::nullopt;
  const std::int64_t height = signedHeight < 0 ? -std::int64_t{signedHeight} : signedHeight;
  if (width <= 0 || height <= 0 || width > kMaxSide || height > kMaxSide ||
      static_cast<std::uint64_t>(width) * static_cast<std::uint64_t>(height) > maxPixels)
    return std::nullopt;
  const int type = bits == 8 ? CV_8UC1 : CV_8UC3;
  if (wanted && !wanted(type)) return std::nullopt;
  b.insert(b.end(), std::istreambuf_iterator<char>(in), {});

  // Rows are padded to 4 bytes; the pixel data must be whole.
  const std::size_t stride = (static_cast<std::size_t>(width) * bits / 8 + 3) & ~std::size_t{3};
  if (pixelsAt > b.size() || (b.size() - pixelsAt) / stride < static_cast<std::size_t>(height))
    return std::nullopt;

  // 8 bits: the palette (B, G, R, reserved per entry) follows the info header and must be grey.
  std::array<unsigned char, 256> grey{};
  std::size_t entries = 0;
  if (bits == 8) {
    entries = paletteUsed == 0 ? 256 : paletteUsed;
    const std::size_t paletteAt = kFileHeader + infoSize;
    if (entries > 256 || paletteAt + 4 * entries > pixelsAt) return std::nullopt;
    for (std::size_t i = 0; i < entries; ++i) {
      const unsigned char* e = &b[paletteAt + 4 * i];
      if (e[0] != e[1] || e[1] != e[2]) return std::nullopt;
      grey[i] = e[0];
    }
  }

  cv::Mat image(static_cast<int>(height), width, type);
  for (std::int64_t row = 0; row < height; ++row) {
    // Bottom-up unless the height is negative.
    const std::int64_t y = signedHeight < 0 ? row : height - 1 - row;
    const unsigned char* src = &b[pixelsAt + static_cast<std::size_t>(row) * stride];
    auto* dst = image.ptr<unsigned char>(static_cast<int>(y));
    if (bits == 24) {
      std::memcpy(dst, src, static_cast<std::size_t>(width) * 3);
      continue;
    }
    for (std::int32_t x = 0; x < width; ++x) {
      if (src[x] >= entries) return std::nullopt;  // outside the palette: the module decides
      dst[x] = grey[src[x]];
    }
  }
  return image;
}

}  // namespace facet
