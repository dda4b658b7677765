#include "camera/png_writer.hpp"

#include <png.h>
#include <zlib.h>

#include <bit>

#include "camera/png_errors.hpp"

namespace facet {
namespace {

void append(png_structp png, png_bytep data, png_size_t length) {
  auto* out = static_cast<std::vector<unsigned char>*>(png_get_io_ptr(png));
  out->insert(out->end(), data, data + length);
}
void flush(png_structp) {}

struct WriteStructs {
  png_structp png = nullptr;
  png_infop info = nullptr;
  ~WriteStructs() {
    if (png) png_destroy_write_struct(&png, info ? &info : nullptr);
  }
};

int colourTypeOf(int channels) {
  switch (channels) {
    case 1:
      return PNG_COLOR_TYPE_GRAY;
    case 3:
      return PNG_COLOR_TYPE_RGB;
    case 4:
      return PNG_COLOR_TYPE_RGB_ALPHA;
    default:
      return -1;
  }
}

bool writeRows(png_structp png, png_infop info, const cv::Mat& image, int colour, int depth,
               std::vector<png_bytep>& rows) {
  if (setjmp(png_jmpbuf(png))) return false;
  png_set_IHDR(png, info, static_cast<png_uint_32>(image.cols),
               static_cast<png_uint_32>(image.rows), depth, colour, PNG_INTERLACE_NONE,
               PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
  png_set_filter(png, PNG_FILTER_TYPE_BASE, PNG_FILTER_SUB);
  png_set_compression_level(png, Z_BEST_SPEED);
  png_set_compression_strategy(png, Z_RLE);
  png_write_info(png, info);
  if (image.channels() >= 3) png_set_bgr(png);
  // PNG stores 16-bit samples big-endian.
  if (depth == 16 && std::endian::native == std::endian::little) png_set_swap(png);
  png_write_image(png, rows.data());
  png_write_end(png, info);
  return true;
}

}  // namespace

std::optional<std::vector<unsigned char>> encodePlainPng(const cv::Mat& image) {
  const int colour = colourTypeOf(image.channels());
  if (image.empty() || image.dims != 2 || colour < 0 ||
      (image.depth() != CV_8U && image.depth() != CV_16U))
    return std::nullopt;
  const int depth = image.depth() == CV_8U ? 8 : 16;
  // libpng reads the rows and writes nothing into them.
  std::vector<png_bytep> rows(static_cast<std::size_t>(image.rows));
  for (int y = 0; y < image.rows; ++y)
    rows[static_cast<std::size_t>(y)] = const_cast<png_bytep>(image.ptr(y));

  std::vector<unsigned char> out;
  WriteStructs s;
  s.png = png_create_write_struct(PNG_LIBPNG_VER_STRING, nullptr, png_errors::jumpBack,
                                  png_errors::ignore);
  if (!s.png) return std::nullopt;
  s.info = png_create_info_struct(s.png);
  if (!s.info) return std::nullopt;
  png_set_write_fn(s.png, &out, append, flush);
  if (!writeRows(s.png, s.info, image, colour, depth, rows)) return std::nullopt;
  return out;
}

}  // namespace facet
