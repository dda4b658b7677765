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
      EXPECT_FALSE(stored->hasExif);
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
    if (!grey->hasExif) {
      EXPECT_TRUE(same(grey->pixels, test::moduleRead(file, cv::IMREAD_GRAYSCALE))) << file;
    }
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

TEST(PlainJpeg, AnExifSegmentIsReported) {
  // An APP1 "Exif" segment right after SOI: cv::imread would apply its orientation to a grey
  // read, so the caller leaves such a read to the module.
  const test::TempFolder dir;
  const auto plain = dir.path() / "plain.jpg";
  ASSERT_TRUE(writeImage(plain, scene(3)));
  std::vector<char> bytes = test::fileBytes(plain);
  const char exif[] = {'\xFF', '\xE1', 0,   16, 'E', 'x', 'i', 'f', 0,
                       0,      'M',    'M', 0,  42,  0,   0,   0,   8};
  bytes.insert(bytes.begin() + 2, std::begin(exif), std::end(exif));
  const auto tagged = dir.path() / "tagged.jpg";
  writeBytes(tagged, bytes);
  const auto read = readPlainJpeg(tagged, 1u << 30, JpegOutput::Stored);
  ASSERT_TRUE(read);
  EXPECT_TRUE(read->hasExif);
  EXPECT_TRUE(same(read->pixels, test::moduleRead(plain, cv::IMREAD_UNCHANGED)));
}

}  // namespace
}  // namespace facet
