// PNGs encoded without the codec module (camera/png_writer.hpp): OpenCV's own decoder in the
// module reads back the very pixels of every kind the encoder takes, and the other kinds are left
// to the module through encodeImage as before.
#include "camera/png_writer.hpp"

#include <gtest/gtest.h>

#include <cstdint>
#include <vector>

#include <opencv2/core.hpp>

#include "camera/image_codecs.hpp"
#include "camera/png_file.hpp"
#include "tests/camera/temp_folder.hpp"

namespace facet {
namespace {

cv::Mat noise(int type, std::uint64_t seed = 3) {
  cv::Mat image(41, 67, type);  // odd sizes: rows are not padded
  cv::RNG rng(seed);
  rng.fill(image, cv::RNG::UNIFORM, 0, CV_MAT_DEPTH(type) == CV_16U ? 65536 : 256);
  return image;
}

bool same(const cv::Mat& a, const cv::Mat& b) {
  return a.size() == b.size() && a.type() == b.type() && cv::norm(a, b, cv::NORM_INF) == 0;
}

cv::Mat moduleDecode(const std::vector<unsigned char>& png) {
  std::vector<unsigned char> copy = png;
  return decodeImage(cv::Mat(1, static_cast<int>(copy.size()), CV_8UC1, copy.data()),
                     cv::IMREAD_UNCHANGED);
}

TEST(PngWriter, OpenCvReadsBackThePixelsOfEveryKindItTakes) {
  ASSERT_EQ(imageCodecsProblem(), "") << "the reference decoder is the module's";
  for (const int type : {CV_8UC1, CV_8UC3, CV_8UC4, CV_16UC1, CV_16UC3, CV_16UC4}) {
    const cv::Mat image = noise(type);
    const auto png = encodePlainPng(image);
    ASSERT_TRUE(png) << cv::typeToString(type);
    EXPECT_TRUE(same(moduleDecode(*png), image)) << cv::typeToString(type);
  }
  // A view into a larger image (rows not contiguous) is encoded as the view.
  const cv::Mat large = noise(CV_8UC3, 5);
  const cv::Mat view = large(cv::Rect(3, 4, 50, 30));
  const auto png = encodePlainPng(view);
  ASSERT_TRUE(png);
  EXPECT_TRUE(same(moduleDecode(*png), view));
}

TEST(PngWriter, LeavesOtherKindsToTheModule) {
  EXPECT_FALSE(encodePlainPng(cv::Mat()));
  EXPECT_FALSE(encodePlainPng(noise(CV_8UC2)));  // grey and alpha: OpenCV has no such PNG
  EXPECT_FALSE(encodePlainPng(cv::Mat(5, 5, CV_32FC1, cv::Scalar(0.5))));
  // encodeImage still answers for them through the module, as cv::imencode does (it takes a
  // float image to 8 bits).
  std::vector<unsigned char> bytes;
  ASSERT_TRUE(encodeImage(".png", cv::Mat(5, 5, CV_32FC1, cv::Scalar(7.0)), bytes));
  const cv::Mat back = moduleDecode(bytes);
  EXPECT_EQ(back.type(), CV_8UC1);
  EXPECT_EQ(cv::countNonZero(back != 7), 0);
}

TEST(PngWriter, EncodeAndWriteImageTakeThePlainPathAndReadBackTheSame) {
  const cv::Mat image = noise(CV_8UC1, 9);
  std::vector<unsigned char> bytes;
  ASSERT_TRUE(encodeImage(".PNG", image, bytes));
  EXPECT_EQ(bytes, *encodePlainPng(image)) << "the in-process encoder, whatever the name's case";
  const test::TempFolder dir;
  const auto file = dir.path() / "written.png";
  ASSERT_TRUE(writeImage(file, image));
  const auto read = readPlainPng(file, 1u << 20);
  ASSERT_TRUE(read);
  EXPECT_TRUE(same(read->pixels, image));
}

}  // namespace
}  // namespace facet
