// convertSensorImage: the single pass from a driver's buffer to a Frame's pixels.

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "camera/sensor_image.hpp"

namespace facet {
namespace {

cv::Mat randomImage(int type, int seed) {
  cv::Mat m(24, 32, type);
  cv::RNG rng(static_cast<std::uint64_t>(seed));
  rng.fill(m, cv::RNG::UNIFORM, 0, CV_MAT_DEPTH(type) == CV_16U ? 65536 : 256);
  return m;
}

bool sameImage(const cv::Mat& a, const cv::Mat& b) {
  return a.size() == b.size() && a.type() == b.type() && cv::norm(a, b, cv::NORM_INF) == 0.0;
}

TEST(SensorImage, OutputOwnsItsPixels) {
  cv::Mat buffer = randomImage(CV_8UC1, 1);
  PixelFormat format{};
  const cv::Mat out =
      convertSensorImage(buffer, SensorLayout::Mono8, ColourConversion::Keep, format);
  EXPECT_EQ(format, PixelFormat::Mono8);
  EXPECT_NE(out.data, buffer.data);
  const cv::Mat before = out.clone();
  buffer.setTo(0);  // the driver reuses its buffer
  EXPECT_TRUE(sameImage(out, before));
}

TEST(SensorImage, BayerFollowsGenICamNaming) {
  const cv::Mat mosaic = randomImage(CV_8UC1, 2);
  const struct {
    SensorLayout layout;
    int bgr;
    int grey;
  } cases[] = {{SensorLayout::BayerRG8, cv::COLOR_BayerBG2BGR, cv::COLOR_BayerBG2GRAY},
               {SensorLayout::BayerGR8, cv::COLOR_BayerGB2BGR, cv::COLOR_BayerGB2GRAY},
               {SensorLayout::BayerGB8, cv::COLOR_BayerGR2BGR, cv::COLOR_BayerGR2GRAY},
               {SensorLayout::BayerBG8, cv::COLOR_BayerRG2BGR, cv::COLOR_BayerRG2GRAY}};
  for (const auto& c : cases) {
    PixelFormat format{};
    cv::Mat expected;
    cv::cvtColor(mosaic, expected, c.bgr);
    EXPECT_TRUE(
        sameImage(convertSensorImage(mosaic, c.layout, ColourConversion::Keep, format), expected));
    EXPECT_EQ(format, PixelFormat::Bgr8);
    cv::cvtColor(mosaic, expected, c.grey);
    EXPECT_TRUE(
        sameImage(convertSensorImage(mosaic, c.layout, ColourConversion::Mono, format), expected));
    EXPECT_EQ(format, PixelFormat::Mono8);
  }
  // GenICam BayerRG8 starts with a red pixel: a mosaic lit only on red sites demosaics to red.
  cv::Mat red_only(8, 8, CV_8UC1, cv::Scalar(0));
  for (int y = 0; y < 8; y += 2)
    for (int x = 0; x < 8; x += 2) red_only.at<std::uint8_t>(y, x) = 200;
  PixelFormat format{};
  const cv::Mat bgr =
      convertSensorImage(red_only, SensorLayout::BayerRG8, ColourConversion::Keep, format);
  const cv::Vec3b centre = bgr.at<cv::Vec3b>(4, 4);
  EXPECT_GT(centre[2], 150);  // R
  EXPECT_LT(centre[0], 50);   // B
}

TEST(SensorImage, Mono16StaysDeepUnlessColourIsAsked) {
  const cv::Mat deep = randomImage(CV_16UC1, 3);
  PixelFormat format{};
  EXPECT_TRUE(sameImage(
      convertSensorImage(deep, SensorLayout::Mono16, ColourConversion::Mono, format), deep));
  EXPECT_EQ(format, PixelFormat::Mono16);
  const cv::Mat colour =
      convertSensorImage(deep, SensorLayout::Mono16, ColourConversion::Colour, format);
  EXPECT_EQ(format, PixelFormat::Bgr8);
  ASSERT_EQ(colour.type(), CV_8UC3);
  const std::uint16_t v = deep.at<std::uint16_t>(5, 7);
  EXPECT_NEAR(colour.at<cv::Vec3b>(5, 7)[1], v / 256.0, 0.51);
}

TEST(SensorImage, RgbBecomesBgrOrGrey) {
  const cv::Mat rgb = randomImage(CV_8UC3, 4);
  PixelFormat format{};
  cv::Mat expected;
  cv::cvtColor(rgb, expected, cv::COLOR_RGB2BGR);
  EXPECT_TRUE(sameImage(convertSensorImage(rgb, SensorLayout::Rgb8, ColourConversion::Keep, format),
                        expected));
  cv::cvtColor(rgb, expected, cv::COLOR_RGB2GRAY);
  EXPECT_TRUE(sameImage(convertSensorImage(rgb, SensorLayout::Rgb8, ColourConversion::Mono, format),
                        expected));
  EXPECT_EQ(format, PixelFormat::Mono8);
}

}  // namespace
}  // namespace facet
