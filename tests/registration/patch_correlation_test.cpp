// correlatePatch against cv::matchTemplate (TM_CCOEFF_NORMED), which it stands in for.
#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

#include "algorithms/registration/patch_correlation.hpp"

namespace facet {
namespace {

TEST(PatchCorrelation, AgreesWithMatchTemplateOnTexturedPatches) {
  cv::RNG rng(11);
  for (const cv::Size search : {cv::Size(31, 31), cv::Size(21, 21), cv::Size(40, 27)}) {
    cv::Mat image(search, CV_32F);
    rng.fill(image, cv::RNG::UNIFORM, 0.0, 1.0);
    cv::GaussianBlur(image, image, cv::Size(), 1.2);  // texture, not white noise
    const cv::Mat patch = image(cv::Rect(5, 6, 15, 15)).clone() * 0.8 + 0.1;
    cv::Mat ours, theirs;
    correlatePatch(image, patch, ours);
    cv::matchTemplate(image, patch, theirs, cv::TM_CCOEFF_NORMED);
    ASSERT_EQ(ours.size(), theirs.size());
    EXPECT_LT(cv::norm(ours, theirs, cv::NORM_INF), 2e-4) << search;
    cv::Point best;
    cv::minMaxLoc(ours, nullptr, nullptr, nullptr, &best);
    EXPECT_EQ(best, cv::Point(5, 6));  // where the patch was cut, at a gain and offset
    EXPECT_NEAR(ours.at<float>(6, 5), 1.0f, 1e-5);
  }
}

TEST(PatchCorrelation, AFlatWindowOrPatchCorrelatesZero) {
  cv::Mat image(25, 25, CV_32F, cv::Scalar(0.5));
  cv::Mat textured(25, 25, CV_32F);
  cv::RNG(3).fill(textured, cv::RNG::UNIFORM, 0.0, 1.0);
  textured(cv::Rect(0, 0, 25, 12)).copyTo(image(cv::Rect(0, 0, 25, 12)));  // flat lower part
  const cv::Mat patch = textured(cv::Rect(2, 2, 9, 9)).clone();
  cv::Mat r;
  correlatePatch(image, patch, r);
  ASSERT_EQ(r.size(), cv::Size(17, 17));
  EXPECT_NEAR(r.at<float>(2, 2), 1.0f, 1e-5);
  EXPECT_EQ(r.at<float>(14, 3), 0.0f);  // the window lies in the flat part
  const cv::Mat flatPatch(9, 9, CV_32F, cv::Scalar(0.3));
  correlatePatch(textured, flatPatch, r);
  EXPECT_EQ(cv::countNonZero(r), 0);
}

}  // namespace
}  // namespace facet
