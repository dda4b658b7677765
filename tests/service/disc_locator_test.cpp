#include <gtest/gtest.h>

#include "algorithms/circle/disc_locator.hpp"
#include "tests/support/scene/scene.hpp"

namespace facet {
namespace {

cv::Mat markOnPlate(cv::Point2d centre, double radius, double markGrey) {
  scene::SceneSpec spec;
  spec.size = {200, 160};
  spec.background = 180;
  spec.blurSigma = 1.0;
  spec.noiseSigma = 2;
  scene::Scene s(spec);
  s.addDisc(centre, radius, markGrey);
  s.addDisc({30, 30}, radius * 1.5, markGrey);  // a larger mark outside the search radius
  return s.render();
}

TEST(DiscLocator, FindsDarkMarkToAPixelWithinTheSearchRadius) {
  const cv::Mat image = markOnPlate({112.3, 77.8}, 8, 40);
  const auto found = locateDisc(image, {.expected = {100, 90},
                                        .radius = 8,
                                        .searchRadius = 25,
                                        .polarity = CirclePolarity::DarkToLight});
  ASSERT_TRUE(found);
  EXPECT_NEAR(found->centre.x, 112.3, 1.0);
  EXPECT_NEAR(found->centre.y, 77.8, 1.0);
  EXPECT_GT(found->score, 0.8);
}

TEST(DiscLocator, WrongPolarityOrTooFarIsNotFound) {
  const cv::Mat image = markOnPlate({112, 78}, 8, 40);
  EXPECT_FALSE(locateDisc(image, {.expected = {100, 90},
                                  .radius = 8,
                                  .searchRadius = 25,
                                  .polarity = CirclePolarity::LightToDark}));
  EXPECT_FALSE(locateDisc(
      image,
      {.expected = {150, 130}, .radius = 8, .searchRadius = 10, .polarity = CirclePolarity::Any}));
  EXPECT_FALSE(locateDisc(cv::Mat(), {.expected = {10, 10}, .radius = 8, .searchRadius = 10}));
}

}  // namespace
}  // namespace facet
