#include "camera/tiff_file.hpp"

#include <algorithm>
#include <cstdarg>
#include <cstdio>
#include <cstring>
#include <limits>
#include <memory>
#include <vector>

#include <tiffio.h>

#include <opencv2/imgproc.hpp>

namespace facet {
namespace {

// The largest single allocation libtiff may make for one file (a strip or tile buffer); a file
// that claims more is damaged or hostile, and left to the module.
constexpr tmsize_t kMaxAllocation = tmsize_t{1} << 30;
constexpr std::uint32_t kMaxSide = std::numeric_limits<int>::max();  // a cv::Mat's

// libtiff reports problems through handlers; these are per file (not the library's global ones),
// so reading in several threads at once is safe. A problem of any kind leaves the file to the
// module, which prints it as cv::imread does.
int onProblem(TIFF*, void* userData, const char*, const char*, va_list) {
  *static_cast<bool*>(userData) = true;
  return 1;  // handled: the library prints nothing
}

struct TiffCloser {
  void operator()(TIFF* tif) const { TIFFClose(tif); }
};
struct OptionsFreer {
  void operator()(TIFFOpenOptions* options) const { TIFFOpenOptionsFree(options); }
};

bool hasTiffSignature(const std::filesystem::path& file) {
  const std::unique_ptr<FILE, int (*)(FILE*)> in(std::fopen(file.c_str(), "rb"), &std::fclose);
  unsigned char head[4];
  if (!in || std::fread(head, 1, sizeof head, in.get()) != sizeof head) return false;
  const bool little = head[0] == 'I' && head[1] == 'I' && (head[2] == 42 || head[2] == 43) &&
                      head[3] == 0;  // classic TIFF or BigTIFF
  const bool big =
      head[0] == 'M' && head[1] == 'M' && head[2] == 0 && (head[3] == 42 || head[3] == 43);
  return little || big;
}

// The layout of a plain file, or nothing.
struct Layout {
  std::uint32_t width = 0, height = 0;
  int channels = 0;  // 1 or 3
  int depth = 0;     // CV_8U or CV_16U
};

std::optional<Layout> plainLayout(TIFF* tif, std::uint64_t maxPixels) {
  std::uint32_t width = 0, height = 0;
  std::uint16_t samples = 1, bits = 1, format = SAMPLEFORMAT_UINT, photometric = 0,
                planar = PLANARCONFIG_CONTIG, compression = COMPRESSION_NONE,
                orientation = ORIENTATION_TOPLEFT, extraCount = 0;
  std::uint16_t* extra = nullptr;
  if (!TIFFGetField(tif, TIFFTAG_IMAGEWIDTH, &width) ||
      !TIFFGetField(tif, TIFFTAG_IMAGELENGTH, &height) ||
      !TIFFGetField(tif, TIFFTAG_PHOTOMETRIC, &photometric))
    return std::nullopt;
  TIFFGetFieldDefaulted(tif, TIFFTAG_SAMPLESPERPIXEL, &samples);
  TIFFGetFieldDefaulted(tif, TIFFTAG_BITSPERSAMPLE, &bits);
  TIFFGetFieldDefaulted(tif, TIFFTAG_SAMPLEFORMAT, &format);
  TIFFGetFieldDefaulted(tif, TIFFTAG_PLANARCONFIG, &planar);
  TIFFGetFieldDefaulted(tif, TIFFTAG_COMPRESSION, &compression);
  TIFFGetFieldDefaulted(tif, TIFFTAG_ORIENTATION, &orientation);
  TIFFGetFieldDefaulted(tif, TIFFTAG_EXTRASAMPLES, &extraCount, &extra);
  const bool grey = photometric == PHOTOMETRIC_MINISBLACK && samples == 1;
  const bool rgb = photometric == PHOTOMETRIC_RGB && samples == 3;
  const bool lossless = compression == COMPRESSION_NONE || compression == COMPRESSION_LZW ||
                        compression == COMPRESSION_ADOBE_DEFLATE ||
                        compression == COMPRESSION_DEFLATE || compression == COMPRESSION_PACKBITS;
  if (!(grey || rgb) || extraCount != 0 || (bits != 8 && bits != 16) ||
      format != SAMPLEFORMAT_UINT || planar != PLANARCONFIG_CONTIG || !lossless ||
      orientation != ORIENTATION_TOPLEFT)
    return std::nullopt;
  if (width == 0 || height == 0 || width > kMaxSide || height > kMaxSide ||
      std::uint64_t{width} * height > maxPixels)
    return std::nullopt;
  return Layout{width, height, samples, bits == 8 ? CV_8U : CV_16U};
}

// Copies a decoded block (a strip, or a tile `blockWidth` pixels wide) whose first row is image
// row `top` and first column `left` into `out`, clipped to the image.
void copyBlock(const std::vector<unsigned char>& block, std::size_t blockRowBytes, int top,
               int left, int rows, cv::Mat& out) {
  const std::size_t pixelBytes = out.elemSize();
  const int columns = std::min(static_cast<int>(blockRowBytes / pixelBytes), out.cols - left);
  for (int r = 0; r < rows && top + r < out.rows; ++r)
    std::memcpy(out.ptr(top + r, left), block.data() + static_cast<std::size_t>(r) * blockRowBytes,
                static_cast<std::size_t>(columns) * pixelBytes);
}

bool readStrips(TIFF* tif, cv::Mat& out) {
  std::uint32_t rowsPerStrip = 0;
  TIFFGetFieldDefaulted(tif, TIFFTAG_ROWSPERSTRIP, &rowsPerStrip);
  const tmsize_t rowBytes = TIFFScanlineSize(tif);
  const tmsize_t stripBytes = TIFFStripSize(tif);
  if (rowsPerStrip == 0 || rowBytes <= 0 || stripBytes <= 0 ||
      static_cast<std::size_t>(rowBytes) < out.cols * out.elemSize())
    return false;
  std::vector<unsigned char> strip(static_cast<std::size_t>(stripBytes));
  // 64-bit positions: a strip or tile may be larger than the image (up to 2^32 - 1 rows).
  const std::uint64_t rows = static_cast<std::uint64_t>(out.rows);
  for (std::uint64_t top = 0; top < rows; top += rowsPerStrip) {
    const std::uint64_t count = std::min<std::uint64_t>(rowsPerStrip, rows - top);
    const tmsize_t wanted = static_cast<tmsize_t>(count) * rowBytes;
    const auto row = static_cast<std::uint32_t>(top);
    if (TIFFReadEncodedStrip(tif, TIFFComputeStrip(tif, row, 0), strip.data(), wanted) != wanted)
      return false;
    copyBlock(strip, static_cast<std::size_t>(rowBytes), static_cast<int>(top), 0,
              static_cast<int>(count), out);
  }
  return true;
}

bool readTiles(TIFF* tif, cv::Mat& out) {
  std::uint32_t tileWidth = 0, tileHeight = 0;
  TIFFGetField(tif, TIFFTAG_TILEWIDTH, &tileWidth);
  TIFFGetField(tif, TIFFTAG_TILELENGTH, &tileHeight);
  const tmsize_t tileBytes = TIFFTileSize(tif);
  const tmsize_t rowBytes = TIFFTileRowSize(tif);
  if (tileWidth == 0 || tileHeight == 0 || tileBytes <= 0 || rowBytes <= 0 ||
      static_cast<std::size_t>(rowBytes) < tileWidth * out.elemSize())
    return false;
  std::vector<unsigned char> tile(static_cast<std::size_t>(tileBytes));
  const int rows = static_cast<int>(std::min<std::uint32_t>(tileHeight, kMaxSide));
  for (std::uint64_t top = 0; top < static_cast<std::uint64_t>(out.rows); top += tileHeight)
    for (std::uint64_t left = 0; left < static_cast<std::uint64_t>(out.cols); left += tileWidth) {
      const auto x = static_cast<std::uint32_t>(left), y = static_cast<std::uint32_t>(top);
      if (TIFFReadEncodedTile(tif, TIFFComputeTile(tif, x, y, 0, 0), tile.data(), tileBytes) !=
          tileBytes)
        return false;
      copyBlock(tile, static_cast<std::size_t>(rowBytes), static_cast<int>(y), static_cast<int>(x),
                rows, out);
    }
  return true;
}

}  // namespace

std::optional<cv::Mat> readPlainTiff(const std::filesystem::path& file, std::uint64_t maxPixels,
                                     const StoredLayoutFilter& wanted) {
  if (!hasTiffSignature(file)) return std::nullopt;
  bool problem = false;
  const std::unique_ptr<TIFFOpenOptions, OptionsFreer> options(TIFFOpenOptionsAlloc());
  if (!options) return std::nullopt;
  TIFFOpenOptionsSetErrorHandlerExtR(options.get(), onProblem, &problem);
  TIFFOpenOptionsSetWarningHandlerExtR(options.get(), onProblem, &problem);
  TIFFOpenOptionsSetMaxSingleMemAlloc(options.get(), kMaxAllocation);
  const std::unique_ptr<TIFF, TiffCloser> tif(TIFFOpenExt(file.c_str(), "r", options.get()));
  if (!tif || problem) return std::nullopt;
  const std::optional<Layout> layout = plainLayout(tif.get(), maxPixels);
  const int type = layout ? CV_MAKETYPE(layout->depth, layout->channels) : -1;
  if (!layout || (wanted && !wanted(type))) return std::nullopt;
  cv::Mat pixels(static_cast<int>(layout->height), static_cast<int>(layout->width), type);
  const bool read =
      TIFFIsTiled(tif.get()) ? readTiles(tif.get(), pixels) : readStrips(tif.get(), pixels);
  if (!read || problem) return std::nullopt;
  if (pixels.channels() == 3) cv::cvtColor(pixels, pixels, cv::COLOR_RGB2BGR);
  return pixels;
}

}  // namespace facet
