// The image-codec facade (camera/image_codecs.hpp): the module is found in the build tree and
// loaded once, also when the first uses race; what goes through it comes back unchanged.
#include "camera/image_codecs.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <thread>
#include <vector>

#include <opencv2/core.hpp>

#include "camera/image_file_reader.hpp"
#include "tests/camera/temp_folder.hpp"

namespace facet {
namespace {

cv::Mat ramp(int type) {
  cv::Mat image(48, 64, type);
  cv::randu(image, 0, CV_MAT_DEPTH(type) == CV_16U ? 65535 : 255);
  return image;
}

bool same(const cv::Mat& a, const cv::Mat& b) {
  return a.size() == b.size() && a.type() == b.type() && cv::norm(a, b, cv::NORM_INF) == 0;
}

TEST(ImageCodecs, TheFirstUsesFromManyThreadsLoadTheModuleOnce) {
  std::vector<std::thread> threads;
  std::atomic<int> decoded = 0;
  const cv::Mat image = ramp(CV_8UC1);
  for (int i = 0; i < 8; ++i) {
    threads.emplace_back([&] {
      std::vector<unsigned char> bytes;
      if (encodeImage(".png", image, bytes) &&
          same(decodeImage(cv::Mat(1, static_cast<int>(bytes.size()), CV_8UC1, bytes.data()),
                           cv::IMREAD_UNCHANGED),
               image))
        ++decoded;
    });
  }
  for (auto& t : threads) t.join();
  EXPECT_EQ(imageCodecsProblem(), "");
  EXPECT_EQ(decoded, 8);
}

TEST(ImageCodecs, WritesAndReadsSixteenBitPngLosslessly) {
  const test::TempFolder folder;
  const cv::Mat image = ramp(CV_16UC1);
  ASSERT_TRUE(writeImage(folder / "deep.png", image)) << imageCodecsProblem();
  EXPECT_TRUE(same(readImage(folder / "deep.png", cv::IMREAD_UNCHANGED), image));
  const ImageFileContent content = readImageFile(folder / "deep.png", 1u << 20);
  ASSERT_TRUE(content.ok()) << content.error;
  EXPECT_EQ(content.format, PixelFormat::Mono16);
  EXPECT_TRUE(same(content.image, image));
}

TEST(ImageCodecs, EncodesJpegThatDecodesToTheSameSize) {
  std::vector<unsigned char> jpeg;
  ASSERT_TRUE(encodeImage(".jpg", ramp(CV_8UC3), jpeg, {cv::IMWRITE_JPEG_QUALITY, 90}));
  const cv::Mat back = decodeImage(cv::Mat(1, static_cast<int>(jpeg.size()), CV_8UC1, jpeg.data()),
                                   cv::IMREAD_COLOR);
  EXPECT_EQ(back.size(), cv::Size(64, 48));
  EXPECT_EQ(back.type(), CV_8UC3);
}

TEST(ImageCodecs, ReadingAFileThatIsNoImageGivesAnEmptyImageAndAnErrorNamingIt) {
  const test::TempFolder folder;
  folder.write("not_an_image.png", "plain text");
  EXPECT_TRUE(readImage(folder / "not_an_image.png").empty());
  const ImageFileContent content = readImageFile(folder / "not_an_image.png", 1u << 20);
  EXPECT_FALSE(content.ok());
  EXPECT_NE(content.error.find("not_an_image.png: cannot read image"), std::string::npos)
      << content.error;
}

}  // namespace
}  // namespace facet
