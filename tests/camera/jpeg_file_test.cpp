// Plain JPEG files read without the codec module (camera/jpeg_file.hpp): the same pixels as the
// module gives, both through OpenCV (as stored, and grey) and through the replay reader
// (OpenImageIO), and every other kind (damaged, too large, not a JPEG) left to the module.
#include "camera/jpeg_file.hpp"

#include <gtest/gtest.h>

#include <cstdint>
#include <fstream>
#include <iterator>
#include <vector>

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
  return a.size() == b.size() && a.type() == b.type() && cv::norm(a, b, cv::NORM_INF) == 0;
}

// A smooth colour image with edges (JPEG's blocks and chroma subsampling both show on it).
cv::Mat scene(int channels) {
  cv::Mat image(61, 83, channels == 3 ? CV_8UC3 : CV_8UC1);
  for (int y = 0; y < image.rows; ++y)
    for (int x = 0; x < image.cols; ++x) {
      const int v = (x * 3 + y * 2) % 256, w = x > 40 ? 220 : 30;
      if (channels == 3)
        image.at<cv::Vec3b>(y, x) = {static_cast<uchar>(v), static_cast<uchar>(w),
                                     static_cast<uchar>(255 - v)};
      else
        image.at<uchar>(y, x) = static_cast<uchar>((v + w) / 2);
    }
  return image;
}

void writeBytes(const std::filesystem::path& file, const std::vector<char>& bytes) {
  std::ofstream(file, std::ios::binary)
      .write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
}

TEST(PlainJpeg, GivesTheModulesPixelsForColourAndGreyFiles) {
  const test::TempFolder dir;
  for (const int channels : {1, 3})
    for (const bool progressive : {false, true}) {
      const auto file =
          dir.path() / ("scene" + std::to_string(channels) + (progressive ? "p" : "") + ".jpg");
      ASSERT_TRUE(writeImage(
          file, scene(channels),
          {cv::IMWRITE_JPEG_QUALITY, 80, cv::IMWRITE_JPEG_PROGRESSIVE, progressive ? 1 : 0}));
      const auto stored = readPlainJpeg(file, 1u << 30, JpegOutput::Stored);
      const auto grey = readPlainJpeg(file, 1u << 30, JpegOutput::Grey);
      ASSERT_TRUE(stored && grey) << file;
      EXPECT_EQ(stored->pixels.channels(), channels);
      EXPECT_EQ(grey->pixels.channels(), 1);
      EXPECT_EQ(stored->orientation, 1);
      EXPECT_TRUE(same(stored->pixels, test::moduleRead(file, cv::IMREAD_UNCHANGED))) << file;
      EXPECT_TRUE(same(grey->pixels, test::moduleRead(file, cv::IMREAD_GRAYSCALE))) << file;
      // The replay reader's result (OpenImageIO in the module) is the stored pixels too.
      EXPECT_TRUE(same(stored->pixels, test::moduleFrame(file))) << file;
      // readImage and readImageFile take this path.
      EXPECT_TRUE(same(readImageFile(file, 1u << 30).image, stored->pixels));
      EXPECT_TRUE(same(readImage(file, cv::IMREAD_UNCHANGED), stored->pixels));
      EXPECT_TRUE(same(readImage(file, cv::IMREAD_GRAYSCALE), grey->pixels));
    }
}

TEST(PlainJpeg, TheRepositorysPhotographsReadAsTheModuleReadsThem) {
  for (const char* name : {"board_source.jpg", "leuvenB.jpg", "pca_test1.jpg"}) {
    const auto file = std::filesystem::path(FACET_TEST_DATA_DIR) / "photos" / name;
    const auto stored = readPlainJpeg(file, 1u << 30, JpegOutput::Stored);
    const auto grey = readPlainJpeg(file, 1u << 30, JpegOutput::Grey);
    ASSERT_TRUE(stored && grey) << file;
    EXPECT_GT(stored->pixels.total(), 10000u);
    EXPECT_TRUE(same(stored->pixels, test::moduleRead(file, cv::IMREAD_UNCHANGED))) << file;
    EXPECT_TRUE(same(stored->pixels, test::moduleFrame(file))) << file;
    EXPECT_TRUE(
        same(readImage(file, cv::IMREAD_GRAYSCALE), test::moduleRead(file, cv::IMREAD_GRAYSCALE)))
        << file;
  }
}

TEST(PlainJpeg, DamagedTruncatedOversizedAndForeignFilesAreLeftToTheModule) {
  const test::TempFolder dir;
  const auto good = dir.path() / "good.jpg";
  ASSERT_TRUE(writeImage(good, scene(3), {cv::IMWRITE_JPEG_QUALITY, 90}));
  const std::vector<char> bytes = test::fileBytes(good);
  ASSERT_TRUE(readPlainJpeg(good, 1u << 30, JpegOutput::Stored));

  // More pixels than allowed: refused before any is decoded.
  EXPECT_FALSE(readPlainJpeg(good, 61 * 83 - 1, JpegOutput::Stored));
  // Cut in the middle of the entropy-coded data: libjpeg warns and pads; left to the module.
  const auto cut = dir.path() / "cut.jpg";
  writeBytes(cut, {bytes.begin(), bytes.begin() + static_cast<std::ptrdiff_t>(bytes.size() / 2)});
  EXPECT_FALSE(readPlainJpeg(cut, 1u << 30, JpegOutput::Stored));
  // Only the start of the header.
  const auto stub = dir.path() / "stub.jpg";
  writeBytes(stub, {bytes.begin(), bytes.begin() + 20});
  EXPECT_FALSE(readPlainJpeg(stub, 1u << 30, JpegOutput::Stored));
  // Not a JPEG at all, and a missing file.
  const auto png = dir.path() / "image.png";
  ASSERT_TRUE(writeImage(png, scene(1)));
  EXPECT_FALSE(readPlainJpeg(png, 1u << 30, JpegOutput::Stored));
  EXPECT_FALSE(readPlainJpeg(dir.path() / "missing.jpg", 1u << 30, JpegOutput::Stored));
}

// An APP1 segment right after SOI holding an Exif block: a TIFF header and one directory with
// a camera make (ASCII, 4 bytes inline) and, unless 0, an orientation.
std::vector<char> exifSegment(bool bigEndian, int orientation) {
  std::vector<unsigned char> tiff;
  const auto u16 = [&](unsigned v) {
    const unsigned char hi = static_cast<unsigned char>(v >> 8), lo = static_cast<unsigned char>(v);
    tiff.insert(tiff.end(), bigEndian ? std::initializer_list<unsigned char>{hi, lo}
                                      : std::initializer_list<unsigned char>{lo, hi});
  };
  const auto u32 = [&](unsigned v) {
    bigEndian ? (u16(v >> 16), u16(v & 0xFFFF)) : (u16(v & 0xFFFF), u16(v >> 16));
  };
  tiff.push_back(bigEndian ? 'M' : 'I');
  tiff.push_back(bigEndian ? 'M' : 'I');
  u16(42);
  u32(8);
  u16(orientation ? 2 : 1);
  u16(271), u16(2), u32(4), tiff.insert(tiff.end(), {'a', 'b', 'c', 0});  // Make "abc"
  if (orientation) u16(274), u16(3), u32(1), u16(static_cast<unsigned>(orientation)), u16(0);
  u32(0);  // no next directory
  std::vector<char> segment = {'\xFF', '\xE1', 0, 0, 'E', 'x', 'i', 'f', 0, 0};
  for (const unsigned char c : tiff) segment.push_back(static_cast<char>(c));
  const std::size_t length = segment.size() - 2;
  segment[2] = static_cast<char>(length >> 8);
  segment[3] = static_cast<char>(length & 0xFF);
  return segment;
}

std::filesystem::path withSegment(const std::filesystem::path& plain, const std::string& name,
                                  const std::vector<char>& segment) {
  std::vector<char> bytes = test::fileBytes(plain);
  bytes.insert(bytes.begin() + 2, segment.begin(), segment.end());
  const auto tagged = plain.parent_path() / name;
  writeBytes(tagged, bytes);
  return tagged;
}

// A camera's JPEG carries an Exif block, usually with an orientation. A grey read applies it as
// cv::imread does, in the process; an unchanged read and the replay reader leave the pixels.
TEST(PlainJpeg, AGreyReadTurnsByTheExifOrientationAsTheModuleDoes) {
  const test::TempFolder dir;
  const auto plain = dir.path() / "plain.jpg";
  ASSERT_TRUE(writeImage(plain, scene(3)));
  const cv::Mat stored = test::moduleRead(plain, cv::IMREAD_UNCHANGED);
  const cv::Mat grey = test::moduleRead(plain, cv::IMREAD_GRAYSCALE);
  int turned = 0;
  for (const bool bigEndian : {false, true})
    for (int orientation = 0; orientation <= 8; ++orientation) {
      const std::string name =
          std::to_string(orientation) + (bigEndian ? "_motorola.jpg" : "_intel.jpg");
      const auto file = withSegment(plain, name, exifSegment(bigEndian, orientation));
      const auto read = readPlainJpeg(file, 1u << 30, JpegOutput::Stored);
      ASSERT_TRUE(read) << name;
      EXPECT_EQ(read->orientation, std::max(orientation, 1)) << name;
      const cv::Mat module = test::moduleRead(file, cv::IMREAD_GRAYSCALE);
      EXPECT_TRUE(same(readImage(file, cv::IMREAD_GRAYSCALE), module)) << name;
      EXPECT_TRUE(same(readImage(file, cv::IMREAD_UNCHANGED), stored)) << name;
      EXPECT_TRUE(same(readImageFile(file, 1u << 30).image, stored)) << name;
      turned += !same(module, grey);
    }
  EXPECT_EQ(turned, 2 * 7);  // the case is real: the module turns orientations 2 to 8
}

// A block the reader does not trust (cut short, not Exif, an orientation out of range) leaves
// a grey read to the module; the pixels as stored are still read in the process.
TEST(PlainJpeg, AnExifBlockItCannotReadIsLeftToTheModule) {
  const test::TempFolder dir;
  const auto plain = dir.path() / "plain.jpg";
  ASSERT_TRUE(writeImage(plain, scene(3)));
  std::vector<char> cutShort = exifSegment(true, 6);
  cutShort.resize(cutShort.size() - 10);
  cutShort[3] = static_cast<char>(cutShort.size() - 2);
  std::vector<char> outOfRange = exifSegment(false, 6);
  outOfRange[outOfRange.size() - 8] = 9;  // the orientation's low byte
  std::vector<char> xmp = {'\xFF', '\xE1', 0, 12, 'h', 't', 't', 'p', ':', '/', '/', 'n', 's', '.'};
  const std::vector<std::pair<std::string, std::vector<char>>> blocks = {
      {"cut.jpg", cutShort}, {"range.jpg", outOfRange}, {"xmp.jpg", xmp}};
  for (const auto& [name, segment] : blocks) {
    const auto file = withSegment(plain, name, segment);
    const auto read = readPlainJpeg(file, 1u << 30, JpegOutput::Stored);
    ASSERT_TRUE(read) << name;
    EXPECT_FALSE(read->orientation) << name;
    EXPECT_TRUE(same(read->pixels, test::moduleRead(plain, cv::IMREAD_UNCHANGED))) << name;
    EXPECT_TRUE(
        same(readImage(file, cv::IMREAD_GRAYSCALE), test::moduleRead(file, cv::IMREAD_GRAYSCALE)))
        << name;
  }
}

}  // namespace
}  // namespace facet
