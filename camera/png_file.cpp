#include "camera/png_file.hpp"

#include <png.h>

#include <bit>
#include <cstdio>
#include <memory>
#include <vector>

#include "camera/png_errors.hpp"

namespace facet {
namespace {

struct Header {
  png_uint_32 width = 0, height = 0;
  int depth = 0, colour = 0, interlace = 0;
  bool transparency = false;
};

bool readHeader(png_structp png, png_infop info, Header& h) {
  if (setjmp(png_jmpbuf(png))) return false;
  png_read_info(png, info);
  png_get_IHDR(png, info, &h.width, &h.height, &h.depth, &h.colour, &h.interlace, nullptr, nullptr);
  h.transparency = png_get_valid(png, info, PNG_INFO_tRNS) != 0;
  return true;
}

bool readRows(png_structp png, png_infop info, png_bytepp rows, bool bgr, bool swap16) {
  if (setjmp(png_jmpbuf(png))) return false;
  if (bgr) png_set_bgr(png);
  if (swap16) png_set_swap(png);
  png_read_update_info(png, info);
  png_read_image(png, rows);
  png_read_end(png, info);  // checks the trailing CRCs and sees an eXIf chunk after the pixels
  return true;
}

struct ReadStructs {
  png_structp png = nullptr;
  png_infop info = nullptr;
  ~ReadStructs() {
    if (png) png_destroy_read_struct(&png, info ? &info : nullptr, nullptr);
  }
};

int channelsOf(int colour) {
  switch (colour) {
    case PNG_COLOR_TYPE_GRAY:
      return 1;
    case PNG_COLOR_TYPE_GRAY_ALPHA:
      return 2;
    case PNG_COLOR_TYPE_RGB:
      return 3;
    case PNG_COLOR_TYPE_RGB_ALPHA:
      return 4;
    default:
      return 0;  // palette: left to the module
  }
}

}  // namespace

std::optional<PlainPng> readPlainPng(const std::filesystem::path& file, std::uint64_t maxPixels,
                                     const StoredLayoutFilter& wanted) {
  const std::unique_ptr<FILE, int (*)(FILE*)> in(std::fopen(file.c_str(), "rb"), &std::fclose);
  if (!in) return std::nullopt;
  unsigned char signature[8];
  if (std::fread(signature, 1, sizeof signature, in.get()) != sizeof signature ||
      png_sig_cmp(signature, 0, sizeof signature) != 0)
    return std::nullopt;

  ReadStructs s;
  s.png = png_create_read_struct(PNG_LIBPNG_VER_STRING, nullptr, png_errors::jumpBack,
                                 png_errors::ignore);
  if (!s.png) return std::nullopt;
  s.info = png_create_info_struct(s.png);
  if (!s.info) return std::nullopt;
  png_init_io(s.png, in.get());
  png_set_sig_bytes(s.png, sizeof signature);

  Header h;
  if (!readHeader(s.png, s.info, h)) return std::nullopt;
  const int channels = channelsOf(h.colour);
  if (channels == 0 || (h.depth != 8 && h.depth != 16) || h.interlace != PNG_INTERLACE_NONE ||
      h.transparency || h.width == 0 || h.height == 0 ||
      static_cast<std::uint64_t>(h.width) * h.height > maxPixels)
    return std::nullopt;
  const int type = CV_MAKETYPE(h.depth == 8 ? CV_8U : CV_16U, channels);
  if (wanted && !wanted(type)) return std::nullopt;

  PlainPng out;
  out.pixels.create(static_cast<int>(h.height), static_cast<int>(h.width), type);
  std::vector<png_bytep> rows(h.height);
  for (png_uint_32 y = 0; y < h.height; ++y) rows[y] = out.pixels.ptr(static_cast<int>(y));
  // PNG stores 16-bit samples big-endian.
  const bool swap16 = h.depth == 16 && std::endian::native == std::endian::little;
  if (!readRows(s.png, s.info, rows.data(), channels >= 3, swap16)) return std::nullopt;
  out.hasExif = png_get_valid(s.png, s.info, PNG_INFO_eXIf) != 0;
  return out;
}

}  // namespace facet
