#include "camera/pgm_file.hpp"

#include <fstream>
#include <string>

namespace facet {
namespace {

constexpr std::int64_t kMaxSide = 1 << 20;
constexpr std::size_t kMaxHeader = 4096;  // comments included; a longer header: the module

bool isSpace(char c) {
  return c == ' ' || c == '\t' || c == '\r' || c == '\n' || c == '\v' || c == '\f';
}

// The header as far as read, and where the next token starts.
struct HeaderCursor {
  const std::string& text;
  std::size_t at = 2;  // after "P5"

  // Skips whitespace and comments (from '#' to the end of the line); false at the end.
  bool skipSeparators() {
    while (at < text.size()) {
      if (isSpace(text[at])) {
        ++at;
      } else if (text[at] == '#') {
        while (at < text.size() && text[at] != '\n' && text[at] != '\r') ++at;
      } else {
        return true;
      }
    }
    return false;
  }
  // A decimal number of at most 7 digits ended by one whitespace character, which is consumed
  // (as OpenCV consumes the character after a number, whatever it is); nullopt otherwise.
  std::optional<std::int64_t> number() {
    if (!skipSeparators()) return std::nullopt;
    std::int64_t value = 0;
    const std::size_t start = at;
    while (at < text.size() && text[at] >= '0' && text[at] <= '9' && at - start < 8)
      value = 10 * value + (text[at++] - '0');
    if (at == start || at - start > 7 || at >= text.size() || !isSpace(text[at]))
      return std::nullopt;
    ++at;
    return value;
  }
};

}  // namespace

std::optional<cv::Mat> readBinaryPgm(const std::filesystem::path& file, std::uint64_t maxPixels,
                                     const StoredLayoutFilter& wanted) {
  std::ifstream in(file, std::ios::binary);
  std::string header(kMaxHeader, '\0');
  in.read(header.data(), static_cast<std::streamsize>(header.size()));
  header.resize(static_cast<std::size_t>(in.gcount()));
  if (header.size() < 3 || header[0] != 'P' || header[1] != '5' || !isSpace(header[2]))
    return std::nullopt;

  HeaderCursor cursor{header};
  const auto width = cursor.number(), height = cursor.number(), maxValue = cursor.number();
  if (!width || !height || !maxValue) return std::nullopt;
  if (*width <= 0 || *height <= 0 || *width > kMaxSide || *height > kMaxSide || *maxValue <= 0 ||
      *maxValue > 65535 ||
      static_cast<std::uint64_t>(*width) * static_cast<std::uint64_t>(*height) > maxPixels)
    return std::nullopt;
  const bool wide = *maxValue > 255;
  const int type = wide ? CV_16UC1 : CV_8UC1;
  if (wanted && !wanted(type)) return std::nullopt;

  cv::Mat image(static_cast<int>(*height), static_cast<int>(*width), type);
  const std::size_t rowBytes = static_cast<std::size_t>(*width) * (wide ? 2 : 1);
  // The samples start right after the whitespace that ends the maximum value.
  in.clear();
  in.seekg(static_cast<std::streamoff>(cursor.at));
  for (int y = 0; y < image.rows; ++y) {
    auto* bytes = image.ptr<unsigned char>(y);
    if (!in.read(reinterpret_cast<char*>(bytes), static_cast<std::streamsize>(rowBytes)))
      return std::nullopt;  // truncated
    if (!wide) continue;
    auto* samples = image.ptr<std::uint16_t>(y);  // each sample replaces its own two bytes
    for (int x = 0; x < image.cols; ++x)
      samples[x] = static_cast<std::uint16_t>(bytes[2 * x] << 8 | bytes[2 * x + 1]);
  }
  return image;
}

}  // namespace facet
