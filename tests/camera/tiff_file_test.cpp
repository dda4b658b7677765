// Plain TIFF files read without the codec module (camera/tiff_file.hpp): the same pixels as the
// module gives, through OpenCV (as stored, and grey) and through the replay reader
// (OpenImageIO), for every bit depth, channel count, lossless compression, byte order and
// layout (strips, tiles) read here; every other kind (palette, min-is-white, alpha, floats, JPEG
// inside TIFF, another orientation, damaged, too large, not a TIFF) left to the module.
#include "camera/tiff_file.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <iterator>
#include <sstream>
#include <string>
#include <vector>

#include <tiffio.h>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "camera/image_codecs.hpp"
#include "camera/image_file_reader.hpp"
#include "tests/camera/module_reference.hpp"
#include "tests/camera/temp_folder.hpp"

namespace facet {
namespace {

bool same(const cv::Mat& a, const cv::Mat& b) {
  if (a.empty() || b.empty()) return a.empty() && b.empty();
  return a.size() == b.size() && a.type() == b.type() && cv::norm(a, b, cv::NORM_INF) == 0;
}

// Samples over the whole range of the depth, with runs (which the compressors shorten) and an
// odd size (partial strips and tiles at the right and bottom).
cv::Mat samples(int depth, int channels) {
  cv::Mat image(45, 37, CV_MAKETYPE(depth, channels));
  cv::RNG rng(depth * 10 + channels);
  rng.fill(image, cv::RNG::UNIFORM, 0, depth == CV_8U ? 256 : 65536);
  image(cv::Rect(5, 5, 20, 12)).setTo(cv::Scalar::all(depth == CV_8U ? 200 : 51000));
  return image;
}

struct Written {
  std::uint16_t compression = COMPRESSION_NONE;
  bool tiled = false;
  bool bigEndian = false;
  int photometric = -1;  // -1: grey or RGB by the channels
  std::uint16_t orientation = ORIENTATION_TOPLEFT;
  std::uint16_t sampleFormat = SAMPLEFORMAT_UINT;
  int extraSamples = 0;  // unassociated alpha after the colour samples
  int pages = 1;
};

// Writes `image` (samples in file order: RGB for colour) with libtiff, as a camera tool would.
void writeTiff(const std::filesystem::path& file, const cv::Mat& image, const Written& w) {
  TIFF* tif = TIFFOpen(file.c_str(), w.bigEndian ? "wb" : "wl");
  ASSERT_NE(tif, nullptr);
  for (int page = 0; page < w.pages; ++page) {
    const int channels = image.channels();
    const int colour = channels - w.extraSamples;
    TIFFSetField(tif, TIFFTAG_IMAGEWIDTH, static_cast<std::uint32_t>(image.cols));
    TIFFSetField(tif, TIFFTAG_IMAGELENGTH, static_cast<std::uint32_t>(image.rows));
    TIFFSetField(tif, TIFFTAG_SAMPLESPERPIXEL, static_cast<std::uint16_t>(channels));
    TIFFSetField(tif, TIFFTAG_BITSPERSAMPLE, static_cast<std::uint16_t>(8 * image.elemSize1()));
    TIFFSetField(tif, TIFFTAG_SAMPLEFORMAT, w.sampleFormat);
    TIFFSetField(tif, TIFFTAG_PHOTOMETRIC,
                 w.photometric >= 0 ? w.photometric
                                    : (colour >= 3 ? PHOTOMETRIC_RGB : PHOTOMETRIC_MINISBLACK));
    TIFFSetField(tif, TIFFTAG_PLANARCONFIG, PLANARCONFIG_CONTIG);
    TIFFSetField(tif, TIFFTAG_COMPRESSION, w.compression);
    TIFFSetField(tif, TIFFTAG_ORIENTATION, w.orientation);
    if (w.extraSamples > 0) {
      const std::uint16_t alpha = EXTRASAMPLE_UNASSALPHA;
      TIFFSetField(tif, TIFFTAG_EXTRASAMPLES, 1, &alpha);
    }
    if (w.photometric == PHOTOMETRIC_PALETTE) {
      std::vector<std::uint16_t> r(256), g(256), b(256);
      for (int i = 0; i < 256; ++i)
        r[i] = static_cast<std::uint16_t>(i * 257),
        g[i] = static_cast<std::uint16_t>(65535 - i * 257), b[i] = 30000;
      TIFFSetField(tif, TIFFTAG_COLORMAP, r.data(), g.data(), b.data());
    }
    if (w.compression == COMPRESSION_JPEG) TIFFSetField(tif, TIFFTAG_JPEGQUALITY, 90);
    if (w.tiled) {
      TIFFSetField(tif, TIFFTAG_TILEWIDTH, 16u);
      TIFFSetField(tif, TIFFTAG_TILELENGTH, 16u);
      std::vector<unsigned char> tile(static_cast<std::size_t>(TIFFTileSize(tif)));
      const std::size_t pixel = image.elemSize();
      for (int y = 0; y < image.rows; y += 16)
        for (int x = 0; x < image.cols; x += 16) {
          std::fill(tile.begin(), tile.end(), 0);
          for (int r = 0; r < 16 && y + r < image.rows; ++r)
            std::memcpy(tile.data() + r * 16 * pixel, image.ptr(y + r, x),
                        std::min(16, image.cols - x) * pixel);
          ASSERT_GE(TIFFWriteEncodedTile(tif, TIFFComputeTile(tif, x, y, 0, 0), tile.data(),
                                         static_cast<tmsize_t>(tile.size())),
                    0);
        }
    } else {
      // 45 rows: the last strip is partial (JPEG's strips hold whole 8-row blocks)
      TIFFSetField(tif, TIFFTAG_ROWSPERSTRIP, w.compression == COMPRESSION_JPEG ? 16u : 7u);
      // libtiff swaps the bytes of a row in place for a big-endian file: write copies.
      std::vector<unsigned char> row(image.cols * image.elemSize());
      for (int y = 0; y < image.rows; ++y) {
        std::memcpy(row.data(), image.ptr(y), row.size());
        ASSERT_EQ(TIFFWriteScanline(tif, row.data(), static_cast<std::uint32_t>(y), 0), 1);
      }
    }
    ASSERT_EQ(TIFFWriteDirectory(tif), 1);
  }
  TIFFClose(tif);
}

cv::Mat inFileOrder(const cv::Mat& bgr) {
  cv::Mat rgb;
  if (bgr.channels() == 3) cv::cvtColor(bgr, rgb, cv::COLOR_BGR2RGB);
  return bgr.channels() == 3 ? rgb : bgr;
}

TEST(PlainTiff, GivesTheModulesPixelsForEveryPlainKind) {
  const test::TempFolder dir;
  int files = 0;
  for (const int depth : {CV_8U, CV_16U})
    for (const int channels : {1, 3})
      for (const std::uint16_t compression :
           {COMPRESSION_NONE, COMPRESSION_LZW, COMPRESSION_ADOBE_DEFLATE, COMPRESSION_PACKBITS})
        for (const bool tiled : {false, true})
          for (const bool bigEndian : {false, true}) {
            const cv::Mat bgr = samples(depth, channels);
            const auto file = dir.path() / (std::to_string(files++) + "_plain.tif");
            Written w;
            w.compression = compression;
            w.tiled = tiled;
            w.bigEndian = bigEndian;
            writeTiff(file, inFileOrder(bgr), w);
            std::ostringstream what;
            what << file.filename().string() << " depth " << depth << " channels " << channels
                 << " compression " << compression << (tiled ? " tiled" : " strips")
                 << (bigEndian ? " big-endian" : " little-endian");
            const auto plain = readPlainTiff(file, 1u << 20);
            ASSERT_TRUE(plain.has_value()) << what.str();
            EXPECT_TRUE(same(*plain, bgr)) << what.str();
            // cv::imdecode of OpenCV 4.6 fails on uncompressed tiled files (its TIFFReadRGBATile
            // call fails); where it reads one, it gives the stored samples too.
            const cv::Mat module = test::moduleRead(file, cv::IMREAD_UNCHANGED);
            if (!module.empty()) {
              EXPECT_TRUE(same(module, bgr)) << what.str();
            }
            EXPECT_TRUE(same(readImage(file, cv::IMREAD_UNCHANGED), bgr)) << what.str();
            for (const int grey :
                 {int(cv::IMREAD_GRAYSCALE), cv::IMREAD_GRAYSCALE | cv::IMREAD_ANYDEPTH}) {
              // Grey as stored; a colour or a 16-bit file read as 8-bit grey: OpenCV's rules.
              const bool stored = channels == 1 && (depth == CV_8U || (grey & cv::IMREAD_ANYDEPTH));
              const cv::Mat moduleGrey = test::moduleRead(file, grey);
              if (!stored && moduleGrey.empty()) continue;  // the imdecode failure above
              EXPECT_TRUE(same(readImage(file, grey), stored ? bgr : moduleGrey))
                  << what.str() << " grey";
              if (stored && !moduleGrey.empty()) {
                EXPECT_TRUE(same(moduleGrey, bgr)) << what.str() << " grey";
              }
            }
            const ImageFileContent frame = readImageFile(file, 1u << 20);
            ASSERT_TRUE(frame.ok()) << what.str() << ": " << frame.error;
            EXPECT_TRUE(same(frame.image, test::moduleFrame(file))) << what.str();
          }
}

// A multi-page file: its first image, as cv::imread and the replay reader take.
TEST(PlainTiff, ReadsTheFirstPage) {
  const test::TempFolder dir;
  const auto file = dir.path() / "pages.tif";
  Written w;
  w.pages = 3;
  const cv::Mat grey = samples(CV_16U, 1);
  writeTiff(file, grey, w);
  const auto plain = readPlainTiff(file, 1u << 20);
  ASSERT_TRUE(plain.has_value());
  EXPECT_TRUE(same(*plain, grey));
  EXPECT_TRUE(same(*plain, test::moduleRead(file, cv::IMREAD_UNCHANGED)));
}

TEST(PlainTiff, LeavesEveryOtherKindToTheModule) {
  const test::TempFolder dir;
  struct Case {
    std::string name;
    cv::Mat image;
    Written written;
    bool moduleReads;  // the module reads it (the fallback gives pixels)
  };
  Written minIsWhite, palette, alpha, floats, jpeg, turned, greyAlpha;
  minIsWhite.photometric = PHOTOMETRIC_MINISWHITE;
  palette.photometric = PHOTOMETRIC_PALETTE;
  alpha.extraSamples = 1;
  greyAlpha.extraSamples = 1;
  floats.sampleFormat = SAMPLEFORMAT_IEEEFP;
  jpeg.compression = COMPRESSION_JPEG;
  turned.orientation = ORIENTATION_BOTRIGHT;
  cv::Mat floatImage;
  samples(CV_16U, 1).convertTo(floatImage, CV_32F, 1.0 / 65535);
  const std::vector<Case> cases = {
      {"min_is_white", samples(CV_8U, 1), minIsWhite, true},
      {"palette", samples(CV_8U, 1), palette, true},
      {"rgba", samples(CV_8U, 4), alpha, true},
      {"grey_alpha", samples(CV_8U, 2), greyAlpha, true},
      {"float", floatImage, floats, true},
      {"jpeg_inside", samples(CV_8U, 3), jpeg, true},
      {"bottom_right_first", samples(CV_8U, 1), turned, true},
  };
  for (const Case& c : cases) {
    const auto file = dir.path() / (c.name + ".tif");
    writeTiff(file, c.image, c.written);
    EXPECT_FALSE(readPlainTiff(file, 1u << 20).has_value()) << c.name;
    // Left to the module, which reads it as it always has.
    const cv::Mat module = test::moduleRead(file, cv::IMREAD_UNCHANGED);
    EXPECT_EQ(!module.empty(), c.moduleReads) << c.name;
    EXPECT_TRUE(same(readImage(file, cv::IMREAD_UNCHANGED), module)) << c.name;
  }

  // Too many pixels for the limit, damaged, not a TIFF at all.
  const auto plainFile = dir.path() / "plain.tif";
  writeTiff(plainFile, samples(CV_8U, 1), Written{});
  EXPECT_TRUE(readPlainTiff(plainFile, 45 * 37).has_value());
  EXPECT_FALSE(readPlainTiff(plainFile, 45 * 37 - 1).has_value());
  std::vector<char> bytes = test::fileBytes(plainFile);
  const auto cut = dir.path() / "cut.tif";
  std::ofstream(cut, std::ios::binary)
      .write(bytes.data(), static_cast<std::streamsize>(bytes.size() / 2));
  EXPECT_FALSE(readPlainTiff(cut, 1u << 20).has_value());
  const auto png = dir.path() / "image.png";
  ASSERT_TRUE(writeImage(png, samples(CV_8U, 1)));
  EXPECT_FALSE(readPlainTiff(png, 1u << 20).has_value());
  EXPECT_FALSE(readPlainTiff(dir.path() / "missing.tif", 1u << 20).has_value());
}

}  // namespace
}  // namespace facet
