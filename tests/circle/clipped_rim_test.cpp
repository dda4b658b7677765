// Rims the sensor clipped (censored_pixels.hpp): an overexposed backlight behind a hole, an
// underexposed light part, in 8 and 16 bits, rendered with exact pixel coverage and the blur
// before pixel integration (a lens's); and the censored pixels' own arithmetic.
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "algorithms/circle/censored_pixels.hpp"
#include "algorithms/circle/circle_measure.hpp"
#include "tests/support/scene/scene.hpp"

namespace facet {
namespace {

// A disc of grey `disc` and radius 30.3 px in a background of grey `background`, both on the
// 8-bit scale and either beyond the sensor's range; blur 1 px before pixel integration, noise 2.
cv::Mat clippedScene(cv::Point2d centre, double background, double disc, std::uint64_t seed,
                     int depth = CV_8U) {
  scene::SceneSpec spec;
  spec.size = {100, 100};
  spec.background = background;
  spec.blurSigma = 1.0;
  spec.blurModel = scene::BlurModel::Lens;
  spec.noiseSigma = 2.0;
  spec.depth = depth;
  spec.subrows = 64;
  spec.seed = seed;
  scene::Scene s(spec);
  s.addDisc(centre, 30.3, disc);
  return s.render();
}

CircleMeasurement measured(const cv::Mat& image, cv::Point2d centre) {
  CircleMeasureParams p;
  p.centre = centre + cv::Point2d(0.6, -0.4);
  p.radius = 30;
  p.width = 5;
  return measureCircle(image, p);
}

// A hole (grey 30) in a backlight 1.6 times the clip (400): a third of the pixels near the rim
// read 255. Fitted as the pixels read, the radius came out 0.57 px small; with the clip in the
// model within 0.06 px (measured 0.006 px bias, 0.022 px RMS over 30 scenes), centre within
// 0.02 px.
TEST(ClippedRim, AHoleInAnOverexposedBacklightIsMeasuredAtItsEdge) {
  for (std::uint64_t seed = 1; seed <= 6; ++seed) {
    const cv::Point2d c{49.6 + 0.07 * seed, 50.2 - 0.05 * seed};
    for (const int depth : {CV_8U, CV_16U}) {
      const CircleMeasurement m = measured(clippedScene(c, 400, 30, seed, depth), c);
      ASSERT_TRUE(m.status.ok()) << m.status.message;
      EXPECT_TRUE(m.greyRefined);
      EXPECT_NEAR(m.radius, 30.3, 0.06) << "seed " << seed << " depth " << depth;
      EXPECT_LT(cv::norm(m.centre - c), 0.02) << "seed " << seed << " depth " << depth;
      EXPECT_GT(m.clippedShare, 0.2);
      EXPECT_LT(m.clippedShare, 0.6);
    }
  }
}

// The same at the other end of the range: a light part (200) on a background the sensor reads
// as 0 (its light 150 grey levels below the black level).
TEST(ClippedRim, ALightDiscOnAnUnderexposedBackgroundToo) {
  for (std::uint64_t seed = 1; seed <= 4; ++seed) {
    const cv::Point2d c{50.3 - 0.06 * seed, 49.7 + 0.08 * seed};
    const CircleMeasurement m = measured(clippedScene(c, -150, 200, seed), c);
    ASSERT_TRUE(m.status.ok()) << m.status.message;
    EXPECT_NEAR(m.radius, 30.3, 0.06) << "seed " << seed;
    EXPECT_LT(cv::norm(m.centre - c), 0.02) << "seed " << seed;
    EXPECT_GT(m.clippedShare, 0.2);
  }
}

// A backlight four times the clip: the step's middle lies beyond 255, the rim is not seen but
// extrapolated, and its edge points alone were 1.34 px inside it. Refused, with the cause.
TEST(ClippedRim, ARimWhoseMiddleIsBeyondTheClipIsRefusedWithTheCause) {
  const cv::Point2d c{50.2, 49.9};
  const CircleMeasurement m = measured(clippedScene(c, 1000, 30, 3), c);
  ASSERT_FALSE(m.status.ok());
  EXPECT_EQ(m.status.cause, CircleFailure::FitTooPoor);
  EXPECT_NE(m.status.message.find("clipped"), std::string::npos) << m.status.message;
  EXPECT_NE(m.status.message.find("exposure"), std::string::npos) << m.status.message;
  EXPECT_GT(m.clippedShare, 0.3);
}

TEST(ClippedRim, ARimWithinTheSensorsRangeHasNoClippedPixels) {
  const cv::Point2d c{50.2, 49.9};
  const CircleMeasurement m = measured(clippedScene(c, 230, 30, 2), c);
  ASSERT_TRUE(m.status.ok()) << m.status.message;
  EXPECT_EQ(m.clippedShare, 0.0);
  EXPECT_NEAR(m.radius, 30.3, 0.02);
}

TEST(CensoredPixels, ZeroOnlyTheResidualsOfPixelsWhoseModelIsBeyondTheirLimit) {
  const std::vector<double> grey{255, 255, 0, 0, 100, 255};
  const CensoredPixels clipped(grey, 255);
  EXPECT_EQ(clipped.size(), 5u);
  // grey - model: the first pixel's model 260 (beyond 255), the second's 250 (short of it); the
  // third's -5 (beyond 0), the fourth's 5; the fifth is not clipped; the sixth's model 255.
  std::vector<double> residuals{-5, 5, 5, -5, -7, 0};
  clipped.censor(residuals);
  EXPECT_EQ(residuals, (std::vector<double>{0, 5, 0, -5, -7, 0}));
  std::vector<double> weights(6, 1.0);
  clipped.unweight(residuals, weights);
  EXPECT_EQ(weights, (std::vector<double>{0, 1, 0, 1, 1, 0}));
  // The noise level of the pixels within the range: the clipped ones' residuals are no noise.
  EXPECT_NEAR(clipped.robustSigma(residuals), 1.4826 * 7.0, 1e-9);
  // A side that reads at a limit starts beyond it by half the step seen; others as they read.
  EXPECT_EQ(CensoredPixels::startingLevel(255, 55, 255), 355);
  EXPECT_EQ(CensoredPixels::startingLevel(0, 100, 255), -50);
  EXPECT_EQ(CensoredPixels::startingLevel(200, 55, 255), 200);
  // A step from 30 up by 400: its middle (230) is seen; by 500 (280) it is not.
  EXPECT_TRUE(clipped.middleSeen(30, 400));
  EXPECT_FALSE(clipped.middleSeen(30, 500));
  // From 430 down by 400 (middle 230) it is; from -100 up by 150 (middle -25) not.
  EXPECT_TRUE(clipped.middleSeen(430, -400));
  EXPECT_FALSE(clipped.middleSeen(-100, 150));
  // Without clipped pixels any step counts as seen: nothing was cut.
  EXPECT_TRUE(CensoredPixels(std::vector<double>{100, 120}, 255).middleSeen(30, 500));
}

}  // namespace
}  // namespace facet
