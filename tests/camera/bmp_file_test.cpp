// Plain BMP files read without the codec module (camera/bmp_file.hpp): the module's pixels, as
// cv::imread and as the replay reader take them, for every plain kind; every other kind (colour
// palette, index outside the palette, compression, 32 bits, truncation, too large) left to the
// module, whose result stands.
#include "camera/bmp_file.hpp"

#include <gtest/gtest.h>

#include <cstdint>
#include <fstream>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "camera/image_codecs.hpp"
#include "camera/image_file_reader.hpp"
#include "tests/camera/module_reference.hpp"
#include "tests/camera/temp_folder.hpp"

namespace facet {
namespace {

bool same(const cv::Mat& a, const cv::Mat& b) {
  return a.size() == b.size() && a.type() == b.type() && cv::norm(a, b, cv::NORM_INF) == 0;
}

cv::Mat noise(int type, std::uint64_t seed = 1) {
  cv::Mat image(37, 53, type);  // odd width: rows are padded to 4 bytes
  cv::RNG rng(seed);
  rng.fill(image, cv::RNG::UNIFORM, 0, 256);
  return image;
}

struct BmpLayout {
  int bits = 8;                    // 8 or 24 (32 for a kind left to the module)
  bool topDown = false;            // a negative height
  std::vector<cv::Vec3b> palette;  // 8 bits: entries as B, G, R
  std::uint32_t compression = 0;   // BI_RGB
  std::size_t cutBytes = 0;        // bytes cut off the end
};

// A BMP written byte by byte: `pixels` are palette indices (8 bits) or B, G, R (24, 32 bits).
void writeBmp(const std::filesystem::path& file, const cv::Mat& pixels, const BmpLayout& l) {
  const int bytesPerPixel = l.bits / 8;
  const std::size_t stride = (static_cast<std::size_t>(pixels.cols) * bytesPerPixel + 3) & ~3u;
  const std::size_t paletteBytes = 4 * l.palette.size();
  const std::uint32_t pixelsAt = 14 + 40 + static_cast<std::uint32_t>(paletteBytes);
  std::vector<unsigned char> b;
  const auto put = [&b](std::uint32_t v, int n) {
    for (int i = 0; i < n; ++i) b.push_back(static_cast<unsigned char>(v >> (8 * i)));
  };
  b.push_back('B'), b.push_back('M');
  put(pixelsAt + static_cast<std::uint32_t>(stride * pixels.rows), 4);
  put(0, 4);
  put(pixelsAt, 4);
  put(40, 4);
  put(static_cast<std::uint32_t>(pixels.cols), 4);
  put(static_cast<std::uint32_t>(l.topDown ? -pixels.rows : pixels.rows), 4);
  put(1, 2);
  put(static_cast<std::uint32_t>(l.bits), 2);
  put(l.compression, 4);
  put(static_cast<std::uint32_t>(stride * pixels.rows), 4);
  put(2835, 4), put(2835, 4);
  put(static_cast<std::uint32_t>(l.palette.size()), 4);
  put(0, 4);
  for (const cv::Vec3b& e : l.palette)
    b.push_back(e[0]), b.push_back(e[1]), b.push_back(e[2]), b.push_back(0);
  for (int row = 0; row < pixels.rows; ++row) {
    const int y = l.topDown ? row : pixels.rows - 1 - row;
    const unsigned char* p = pixels.ptr<unsigned char>(y);
    b.insert(b.end(), p, p + static_cast<std::size_t>(pixels.cols) * bytesPerPixel);
    b.resize(b.size() + stride - static_cast<std::size_t>(pixels.cols) * bytesPerPixel, 0);
  }
  b.resize(b.size() - l.cutBytes);
  std::ofstream(file, std::ios::binary)
      .write(reinterpret_cast<const char*>(b.data()), static_cast<std::streamsize>(b.size()));
}

std::vector<cv::Vec3b> greyPalette(int entries, bool inverted) {
  std::vector<cv::Vec3b> palette;
  for (int i = 0; i < entries; ++i) {
    const auto v = static_cast<unsigned char>(inverted ? 255 - i : i);
    palette.emplace_back(v, v, v);
  }
  return palette;
}

// Every read facet makes of `file` equals the module's, and the in-process reader took it.
void expectTheModulesPixels(const std::filesystem::path& file, const cv::Mat& expected) {
  const auto plain = readPlainBmp(file, 1u << 20);
  ASSERT_TRUE(plain.has_value());
  EXPECT_TRUE(same(*plain, expected));
  EXPECT_TRUE(same(test::moduleRead(file, cv::IMREAD_UNCHANGED), expected));
  EXPECT_TRUE(same(readImage(file, cv::IMREAD_UNCHANGED), expected));
  const cv::Mat moduleGrey = test::moduleRead(file, cv::IMREAD_GRAYSCALE);
  EXPECT_TRUE(same(readImage(file, cv::IMREAD_GRAYSCALE), moduleGrey));
  const ImageFileContent frame = readImageFile(file, 1u << 20);
  ASSERT_TRUE(frame.ok()) << frame.error;
  EXPECT_TRUE(same(frame.image, test::moduleFrame(file)));
}

TEST(PlainBmp, ReadsWhatTheModuleWritesAsTheModuleReadsIt) {
  const test::TempFolder dir;
  for (const int type : {CV_8UC1, CV_8UC3}) {
    SCOPED_TRACE(cv::typeToString(type));
    const cv::Mat image = noise(type);
    const auto file = dir / "written.bmp";
    ASSERT_TRUE(writeImage(file, image)) << imageCodecsProblem();
    expectTheModulesPixels(file, image);
  }
}

TEST(PlainBmp, TopDownRowsAndAnyGreyPalette) {
  const test::TempFolder dir;
  const cv::Mat indices = noise(CV_8UC1, 2);
  cv::Mat inverted = 255 - indices;
  for (const bool topDown : {false, true}) {
    SCOPED_TRACE(topDown ? "top-down" : "bottom-up");
    const auto file = dir / "palette.bmp";
    writeBmp(file, indices, {8, topDown, greyPalette(256, true)});
    expectTheModulesPixels(file, inverted);
    writeBmp(file, noise(CV_8UC3, 3), {24, topDown});
    expectTheModulesPixels(file, noise(CV_8UC3, 3));
  }
}

TEST(PlainBmp, OtherKindsAreLeftToTheModule) {
  const test::TempFolder dir;
  const cv::Mat indices = noise(CV_8UC1, 4) / 64;  // 0..3
  const auto refused = [&](const std::string& name, const cv::Mat& pixels, const BmpLayout& l) {
    SCOPED_TRACE(name);
    const auto file = dir / (name + ".bmp");
    writeBmp(file, pixels, l);
    EXPECT_FALSE(readPlainBmp(file, 1u << 20).has_value());
    // What facet reads is the module's, whatever it is (an empty image for a damaged file).
    EXPECT_TRUE(
        same(readImage(file, cv::IMREAD_UNCHANGED), test::moduleRead(file, cv::IMREAD_UNCHANGED)));
  };
  std::vector<cv::Vec3b> colour = greyPalette(4, false);
  colour[2] = {10, 200, 30};
  refused("colour_palette", indices, {8, false, colour});
  refused("index_outside_palette", indices, {8, false, greyPalette(2, false)});
  refused("run_length", indices, {8, false, greyPalette(4, false), 1});
  refused("thirty_two_bits", noise(CV_8UC4), {32});
  refused("truncated", indices, {8, false, greyPalette(4, false), 0, 40});
  const auto file = dir / "large.bmp";
  writeBmp(file, noise(CV_8UC3), {24});
  EXPECT_FALSE(readPlainBmp(file, 37 * 53 - 1).has_value()) << "more pixels than allowed";
  EXPECT_TRUE(readPlainBmp(file, 37 * 53).has_value());
}

}  // namespace
}  // namespace facet
