// The relative defocus of two views of one scene (the re-matching that uses it: registration_test).
#include <cmath>

#include <gtest/gtest.h>

#include "algorithms/registration/relative_defocus.hpp"
#include "tests/registration/textured_scene.hpp"

namespace facet {
namespace {

using testing::texturedScene;

cv::Mat unitScene(int seed) {
  cv::Mat f;
  texturedScene({400, 400}, seed).convertTo(f, CV_32F, 1.0 / 255);
  return f;
}

TEST(RelativeDefocus, FindsTheBlurOfABlurredCopyAndWhichViewIsTheSharper) {
  const cv::Mat mask(400, 400, CV_8U, cv::Scalar(255));
  for (const double sigma : {1.0, 2.0, 3.5}) {
    const cv::Mat sharp = unitScene(7);
    cv::Mat blurred;
    cv::GaussianBlur(sharp, blurred, cv::Size(), sigma, sigma, cv::BORDER_REFLECT);
    EXPECT_NEAR(relativeDefocus(sharp, blurred, mask), sigma, 0.15 * sigma) << sigma;
    EXPECT_NEAR(relativeDefocus(blurred, sharp, mask), -sigma, 0.15 * sigma) << sigma;
  }
}

TEST(RelativeDefocus, AChangeOfContrastOrExposureIsNoDefocus) {
  const cv::Mat mask(400, 400, CV_8U, cv::Scalar(255));
  const cv::Mat a = unitScene(8);
  const cv::Mat b = 0.4 * a + 0.3;
  EXPECT_EQ(relativeDefocus(a, b, mask), 0.0);
  EXPECT_EQ(relativeDefocus(a, a, cv::Mat(400, 400, CV_8U, cv::Scalar(0))), 0.0);  // no overlap
}

}  // namespace
}  // namespace facet
