// Plain PNG files read without the codec module (camera/png_file.hpp): the same pixels and pixel
// format as the module gives for every kind it takes, and every other kind (palette, transparency,
// interlaced, fewer bits, damaged, too large) left to the module, whose result stands.
#include "camera/png_file.hpp"

#include <png.h>

#include <gtest/gtest.h>

#include <cstdint>
#include <cstdio>
#include <fstream>
#include <vector>

#include <opencv2/core.hpp>

#include "camera/image_codecs.hpp"
#include "camera/image_file_reader.hpp"
#include "tests/camera/temp_folder.hpp"

namespace facet {
namespace {

cv::Mat noise(int type, std::uint64_t seed = 1) {
  cv::Mat image(37, 53, type);  // odd sizes: rows are not padded
  cv::RNG rng(seed);            // the same pixels in every process
  rng.fill(image, cv::RNG::UNIFORM, 0, CV_MAT_DEPTH(type) == CV_16U ? 65536 : 256);
  return image;
}

bool same(const cv::Mat& a, const cv::Mat& b) {
  return a.size() == b.size() && a.type() == b.type() && cv::norm(a, b, cv::NORM_INF) == 0;
}

// A PNG written with libpng itself, for the kinds OpenCV's writer does not make. `samples` holds
// the rows as PNG stores them (8-bit samples; packed for fewer bits).
void writePng(const std::filesystem::path& file, int width, int height, int colour, int depth,
              const std::vector<unsigned char>& samples, int interlace = PNG_INTERLACE_NONE,
              bool transparency = false) {
  FILE* out = std::fopen(file.c_str(), "wb");
  ASSERT_NE(out, nullptr);
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
  png_infop info = png_create_info_struct(png);
  png_init_io(png, out);
  png_set_IHDR(png, info, width, height, depth, colour, interlace, PNG_COMPRESSION_TYPE_DEFAULT,
               PNG_FILTER_TYPE_DEFAULT);
  std::vector<png_color> palette(4, png_color{10, 200, 30});
  if (colour == PNG_COLOR_TYPE_PALETTE) png_set_PLTE(png, info, palette.data(), 4);
  png_color_16 key{0, 0, 0, 0, 7};
  if (transparency) png_set_tRNS(png, info, nullptr, 0, &key);
  png_write_info(png, info);
  const std::size_t stride = samples.size() / static_cast<std::size_t>(height);
  std::vector<png_bytep> rows;
  for (int y = 0; y < height; ++y)
    rows.push_back(const_cast<png_bytep>(samples.data()) + static_cast<std::size_t>(y) * stride);
  png_write_image(png, rows.data());
  png_write_end(png, nullptr);
  png_destroy_write_struct(&png, &info);
  std::fclose(out);
}

std::vector<unsigned char> bytesOf(const cv::Mat& m) {
  return {m.datastart, m.dataend};
}

TEST(PlainPng, ReadsEveryDepthAndChannelCountAsTheModuleDoes) {
  const test::TempFolder folder;
  for (const int type : {CV_8UC1, CV_16UC1, CV_8UC3, CV_16UC3, CV_8UC4, CV_16UC4}) {
    SCOPED_TRACE(cv::typeToString(type));
    const cv::Mat image = noise(type);
    // The module writes both: OpenCV's PNG encoder, and a TIFF its OpenImageIO reads back.
    ASSERT_TRUE(writeImage(folder / "a.png", image)) << imageCodecsProblem();
    ASSERT_TRUE(writeImage(folder / "a.tif", image));

    const auto plain = readPlainPng(folder / "a.png", 1u << 20);
    ASSERT_TRUE(plain.has_value());
    EXPECT_TRUE(same(plain->pixels, image));  // OpenCV's channel order and byte order
    EXPECT_TRUE(same(readImage(folder / "a.png", cv::IMREAD_UNCHANGED), image));

    const ImageFileContent fromPng = readImageFile(folder / "a.png", 1u << 20);
    const ImageFileContent fromTiff = readImageFile(folder / "a.tif", 1u << 20);
    ASSERT_TRUE(fromPng.ok()) << fromPng.error;
    ASSERT_TRUE(fromTiff.ok()) << fromTiff.error;
    EXPECT_EQ(fromPng.format, fromTiff.format);
    EXPECT_TRUE(same(fromPng.image, fromTiff.image));
  }
}

TEST(PlainPng, GreyWithAlphaKeepsTheGreyForAFrame) {
  const test::TempFolder folder;
  const cv::Mat grey = noise(CV_8UC1, 2), alpha = noise(CV_8UC1, 3);
  cv::Mat both;
  cv::merge(std::vector<cv::Mat>{grey, alpha}, both);
  writePng(folder / "ga.png", grey.cols, grey.rows, PNG_COLOR_TYPE_GRAY_ALPHA, 8, bytesOf(both));
  const auto plain = readPlainPng(folder / "ga.png", 1u << 20);
  ASSERT_TRUE(plain.has_value());
  EXPECT_TRUE(same(plain->pixels, both));
  const ImageFileContent frame = readImageFile(folder / "ga.png", 1u << 20);
  ASSERT_TRUE(frame.ok()) << frame.error;
  EXPECT_EQ(frame.format, PixelFormat::Mono8);
  EXPECT_TRUE(same(frame.image, grey));
}

// A caller that would pass a layout on says so before the pixels are decoded.
TEST(PlainPng, ALayoutTheCallerRefusesIsNotRead) {
  const test::TempFolder folder;
  ASSERT_TRUE(writeImage(folder / "colour.png", noise(CV_16UC3, 4))) << imageCodecsProblem();
  int asked = -1;
  const auto refused = readPlainPng(folder / "colour.png", 1u << 20, [&](int type) {
    asked = type;
    return CV_MAT_CN(type) == 1;
  });
  EXPECT_FALSE(refused.has_value());
  EXPECT_EQ(asked, CV_16UC3);
  const auto accepted =
      readPlainPng(folder / "colour.png", 1u << 20, [](int type) { return type == CV_16UC3; });
  ASSERT_TRUE(accepted.has_value());
  EXPECT_EQ(accepted->pixels.type(), CV_16UC3);
}

TEST(PlainPng, OtherKindsAreLeftToTheModuleWhichReadsThem) {
  const test::TempFolder folder;
  const int w = 16, h = 9;
  cv::Mat grey = noise(CV_8UC1)(cv::Rect(0, 0, w, h)).clone();
  // The module's reader (OpenImageIO) turns pixels of the transparent key (7, below) into 0: it
  // premultiplies by the alpha the key stands for. No pixel takes the key here.
  grey.setTo(8, grey == 7);
  writePng(folder / "interlaced.png", w, h, PNG_COLOR_TYPE_GRAY, 8, bytesOf(grey),
           PNG_INTERLACE_ADAM7);
  writePng(folder / "keyed.png", w, h, PNG_COLOR_TYPE_GRAY, 8, bytesOf(grey), PNG_INTERLACE_NONE,
           true);
  writePng(folder / "palette.png", w, h, PNG_COLOR_TYPE_PALETTE, 8,
           std::vector<unsigned char>(w * h, 2));
  writePng(folder / "two_bit.png", w, h, PNG_COLOR_TYPE_GRAY, 2,
           std::vector<unsigned char>(w / 4 * h, 0xe4));
  for (const char* name : {"interlaced.png", "keyed.png", "palette.png", "two_bit.png"}) {
    SCOPED_TRACE(name);
    EXPECT_FALSE(readPlainPng(folder / name, 1u << 20).has_value());
    const ImageFileContent frame = readImageFile(folder / name, 1u << 20);
    ASSERT_TRUE(frame.ok()) << frame.error;
    EXPECT_EQ(frame.image.size(), cv::Size(w, h));
  }
  EXPECT_TRUE(same(readImageFile(folder / "interlaced.png", 1u << 20).image, grey));
  EXPECT_TRUE(same(readImageFile(folder / "keyed.png", 1u << 20).image, grey));
  EXPECT_EQ(readImageFile(folder / "palette.png", 1u << 20).format, PixelFormat::Bgr8);
}

TEST(PlainPng, DamagedOrTooLargeFilesGetTheModulesErrorNamingTheFile) {
  const test::TempFolder folder;
  ASSERT_TRUE(writeImage(folder / "whole.png", noise(CV_8UC1)));
  std::ifstream in(folder / "whole.png", std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  folder.write("cut.png", bytes.substr(0, bytes.size() / 2));
  std::string flipped = bytes;
  flipped[bytes.size() / 2] = static_cast<char>(~flipped[bytes.size() / 2]);  // a CRC fails
  folder.write("flipped.png", flipped);

  folder.write("text.png", "not an image");

  // readPlainPng gives up on each, libpng's longjmp included (a cut file).
  for (const char* name : {"cut.png", "flipped.png", "text.png"})
    EXPECT_FALSE(readPlainPng(folder / name, 1u << 20).has_value()) << name;
  // The module words the error. Not on the cut file: OpenImageIO 2.4 leaks its error string when
  // libpng stops reading a truncated PNG, which the ASan phase would report as ours.
  for (const char* name : {"flipped.png", "text.png"}) {
    SCOPED_TRACE(name);
    const ImageFileContent frame = readImageFile(folder / name, 1u << 20);
    EXPECT_FALSE(frame.ok());
    EXPECT_NE(frame.error.find(name), std::string::npos) << frame.error;
    EXPECT_TRUE(frame.image.empty());
  }
  EXPECT_FALSE(readPlainPng(folder / "whole.png", 100).has_value());
  const ImageFileContent large = readImageFile(folder / "whole.png", 100);
  EXPECT_NE(large.error.find("exceeds the limit of 100 pixels"), std::string::npos) << large.error;
  EXPECT_FALSE(readPlainPng(folder / "missing.png", 1u << 20).has_value());
}

TEST(PlainPng, GreyscaleReadsOfColourFilesGoThroughTheModule) {
  const test::TempFolder folder;
  const cv::Mat colour = noise(CV_8UC3, 4), deep = noise(CV_16UC1, 5);
  ASSERT_TRUE(writeImage(folder / "colour.png", colour));
  ASSERT_TRUE(writeImage(folder / "deep.png", deep));
  // OpenCV's own conversions: the same as decoding the bytes in the module.
  auto decoded = [&](const char* name, int flags) {
    std::ifstream in(folder / name, std::ios::binary);
    std::vector<unsigned char> b((std::istreambuf_iterator<char>(in)),
                                 std::istreambuf_iterator<char>());
    return decodeImage(cv::Mat(1, static_cast<int>(b.size()), CV_8UC1, b.data()), flags);
  };
  for (const int flags : std::vector<int>{
           cv::IMREAD_GRAYSCALE, cv::IMREAD_GRAYSCALE | cv::IMREAD_ANYDEPTH, cv::IMREAD_COLOR}) {
    SCOPED_TRACE(flags);
    EXPECT_TRUE(same(readImage(folder / "colour.png", flags), decoded("colour.png", flags)));
    EXPECT_TRUE(same(readImage(folder / "deep.png", flags), decoded("deep.png", flags)));
  }
  EXPECT_TRUE(
      same(readImage(folder / "deep.png", cv::IMREAD_GRAYSCALE | cv::IMREAD_ANYDEPTH), deep));
}

}  // namespace
}  // namespace facet
