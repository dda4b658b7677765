// The cubic facet fit reproduces any bicubic exactly, and its zero crossing finds the inflection
// of a cubic step profile.
#include <cmath>

#include <gtest/gtest.h>

#include "algorithms/edges/facet_model.hpp"

namespace facet {
namespace {

TEST(CubicFacet, ReproducesABicubicExactly) {
  const FacetCoefficients k = {50, 3, -2, 0.5, 0.25, -0.75, 0.05, -0.02, 0.03, -0.04};
  cv::Mat image(9, 9, CV_16U);
  const cv::Point c(4, 4);
  for (int y = 0; y < 9; ++y)
    for (int x = 0; x < 9; ++x) {
      const double u = x - c.x, v = y - c.y;
      const double f = k[0] + k[1] * u + k[2] * v + k[3] * u * u + k[4] * u * v + k[5] * v * v +
                       k[6] * u * u * u + k[7] * u * u * v + k[8] * u * v * v + k[9] * v * v * v;
      image.at<ushort>(y, x) = static_cast<ushort>(std::lround(f * 256));  // 16-bit = 8-bit * 256
    }
  const FacetCoefficients got = fitCubicFacet(image, c);
  for (int i = 0; i < 10; ++i) EXPECT_NEAR(got[i], k[i], 2e-3) << "coefficient " << i;
}

TEST(CubicFacet, ZeroCrossingOfACubicRampIsItsInflection) {
  // f(x) = 100 + 20 (x - 0.3) - 2 (x - 0.3)^3 along x: inflection at x = 0.3.
  cv::Mat image(7, 7, CV_8U);
  for (int y = 0; y < 7; ++y)
    for (int x = 0; x < 7; ++x) {
      const double u = x - 3 - 0.3;
      image.at<uchar>(y, x) = cv::saturate_cast<uchar>(100 + 20 * u - 2 * u * u * u);
    }
  const auto z = facetZeroCrossing(fitCubicFacet(image, {3, 3}));
  ASSERT_TRUE(z.has_value());
  EXPECT_NEAR(z->normal.x, 1.0, 1e-6);
  EXPECT_NEAR(z->rho, 0.3, 0.02);  // rounding to 8 bits
}

TEST(CubicFacet, FlatNeighbourhoodHasNoZeroCrossing) {
  const cv::Mat image(7, 7, CV_8U, cv::Scalar(77));
  EXPECT_FALSE(facetZeroCrossing(fitCubicFacet(image, {3, 3})).has_value());
}

}  // namespace
}  // namespace facet
