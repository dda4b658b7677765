// Binary PGM files read without the codec module (camera/pgm_file.hpp): the module's samples, as
// cv::imread and as the replay reader take them, for 8 and 16 bits and every header layout
// OpenCV reads the same way; every other kind (ASCII or colour PNM, a header OpenCV reads
// differently or refuses, truncation, too large) left to the module, whose result stands.
#include "camera/pgm_file.hpp"

#include <gtest/gtest.h>

#include <cstdint>
#include <fstream>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "camera/decoded_frame.hpp"
#include "camera/image_codecs.hpp"
#include "camera/image_file_reader.hpp"
#include "tests/camera/module_reference.hpp"
#include "tests/camera/temp_folder.hpp"

namespace facet {
namespace {

bool same(const cv::Mat& a, const cv::Mat& b) {
  return a.size() == b.size() && a.type() == b.type() && cv::norm(a, b, cv::NORM_INF) == 0;
}

cv::Mat noise(int type, double high, std::uint64_t seed = 1) {
  cv::Mat image(37, 53, type);
  cv::RNG rng(seed);
  rng.fill(image, cv::RNG::UNIFORM, 0, high);
  return image;
}

// A PNM written byte by byte: `header` as given, then the samples (two bytes each, most
// significant first, for CV_16U), `cutBytes` cut off the end.
void writePgm(const std::filesystem::path& file, const std::string& header, const cv::Mat& samples,
              std::size_t cutBytes = 0) {
  std::vector<unsigned char> b(header.begin(), header.end());
  for (int y = 0; y < samples.rows; ++y) {
    if (samples.depth() == CV_8U) {
      const unsigned char* row = samples.ptr<unsigned char>(y);
      b.insert(b.end(), row, row + samples.cols * samples.channels());
      continue;
    }
    for (int x = 0; x < samples.cols; ++x) {
      const std::uint16_t v = samples.at<std::uint16_t>(y, x);
      b.push_back(static_cast<unsigned char>(v >> 8));
      b.push_back(static_cast<unsigned char>(v & 0xff));
    }
  }
  b.resize(b.size() - cutBytes);
  std::ofstream(file, std::ios::binary)
      .write(reinterpret_cast<const char*>(b.data()), static_cast<std::streamsize>(b.size()));
}

// Every read facet makes of `file` equals the module's, and the in-process reader took it.
void expectTheModulesSamples(const std::filesystem::path& file, const cv::Mat& expected) {
  const auto plain = readBinaryPgm(file, 1u << 20);
  ASSERT_TRUE(plain.has_value());
  EXPECT_TRUE(same(*plain, expected));
  EXPECT_TRUE(same(test::moduleRead(file, cv::IMREAD_UNCHANGED), expected));
  EXPECT_TRUE(same(readImage(file, cv::IMREAD_UNCHANGED), expected));
  for (const int flags : {int{cv::IMREAD_GRAYSCALE}, cv::IMREAD_GRAYSCALE | cv::IMREAD_ANYDEPTH})
    EXPECT_TRUE(same(readImage(file, flags), test::moduleRead(file, flags))) << flags;
  // The module's replay reader takes PNM samples from OpenCV (image_file_decoder.cpp).
  const ImageFileContent frame = readImageFile(file, 1u << 20);
  ASSERT_TRUE(frame.ok()) << frame.error;
  EXPECT_TRUE(
      same(frame.image, frameOfDecodedPixels(test::moduleRead(file, cv::IMREAD_UNCHANGED)).image));
}

TEST(BinaryPgm, ReadsWhatTheModuleWritesAsTheModuleReadsIt) {
  const test::TempFolder dir;
  for (const int type : {CV_8UC1, CV_16UC1}) {
    SCOPED_TRACE(cv::typeToString(type));
    const cv::Mat image = noise(type, type == CV_8UC1 ? 256 : 65536);
    const auto file = dir / "written.pgm";
    ASSERT_TRUE(writeImage(file, image)) << imageCodecsProblem();
    expectTheModulesSamples(file, image);
  }
}

TEST(BinaryPgm, CommentsAnyWhitespaceAndAnyMaximumKeepTheSamplesAsStored) {
  const test::TempFolder dir;
  const auto file = dir / "header.pgm";
  const cv::Mat low = noise(CV_8UC1, 256, 2);  // above a maximum of 100 too: kept as stored
  writePgm(file, "P5\n# written by a line camera\n53 37\n100\n", low);
  expectTheModulesSamples(file, low);
  writePgm(file, "P5\r\n53\t37 # width, height\r\n 255\r", low);
  expectTheModulesSamples(file, low);
  const cv::Mat twelveBits = noise(CV_16UC1, 4096, 3);
  writePgm(file, "P5 53 37 4095\n", twelveBits);
  expectTheModulesSamples(file, twelveBits);
  const cv::Mat full = noise(CV_16UC1, 65536, 4);
  writePgm(file, "P5\n53 37\n65535\n", full);
  expectTheModulesSamples(file, full);
}

TEST(BinaryPgm, OtherKindsAreLeftToTheModule) {
  const test::TempFolder dir;
  const cv::Mat grey = noise(CV_8UC1, 256, 5);
  const auto refused = [&](const std::string& name, const std::string& header,
                           const cv::Mat& samples, std::size_t cutBytes = 0) {
    SCOPED_TRACE(name);
    const auto file = dir / (name + ".pgm");
    writePgm(file, header, samples, cutBytes);
    EXPECT_FALSE(readBinaryPgm(file, 1u << 20).has_value());
    // What facet reads is the module's, whatever it is (an empty image for a damaged file).
    EXPECT_TRUE(
        same(readImage(file, cv::IMREAD_UNCHANGED), test::moduleRead(file, cv::IMREAD_UNCHANGED)));
  };
  refused("ascii", "P2\n2 1\n255\n10 200\n", cv::Mat());
  refused("colour", "P6\n53 37\n255\n", noise(CV_8UC3, 256, 6));
  refused("truncated", "P5\n53 37\n255\n", grey, 40);
  refused("comment_after_magic", "P5# no space\n53 37\n255\n", grey);
  refused("comment_ends_a_number", "P5\n53# width\n37\n255\n", grey);
  refused("maximum_zero", "P5\n53 37\n0\n", grey);
  refused("maximum_above_16_bits", "P5\n53 37\n70000\n", grey);
  refused("no_width", "P5\n\n", cv::Mat());
  const auto file = dir / "large.pgm";
  writePgm(file, "P5\n53 37\n255\n", grey);
  EXPECT_FALSE(readBinaryPgm(file, 37 * 53 - 1).has_value()) << "more pixels than allowed";
  EXPECT_TRUE(readBinaryPgm(file, 37 * 53).has_value());
}

}  // namespace
}  // namespace facet
