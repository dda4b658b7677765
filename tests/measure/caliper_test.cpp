// Caliper: edges at subpixel positions at any angle and under both blur models, pairs, selection,
// the arc variant, and every failure with its cause.
#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "algorithms/measure/caliper.hpp"
#include "tests/measure/edge_images.hpp"

namespace facet {
namespace {

using test::axisOf;

TEST(Caliper, FindsAnEdgeAtSubpixelPositionAtAnyAngle) {
  for (double angle : {0.0, 17.0, 45.0, 90.0, 133.3, 200.0, 271.0}) {
    const MeasuringRect rect{40.3, 39.6, 40, 20, angle};
    const double truth = 3.37;  // the edge crosses the axis here
    const cv::Point2d at = cv::Point2d(rect.cx, rect.cy) + truth * axisOf(angle);
    const cv::Mat image =
        test::gridEdgeImage({80, 80}, at, axisOf(angle + 3.0), 50, 170, 1.0, 1.0, 7);
    const CaliperResult r = measureCaliper(image, MeasuringPath(rect));
    ASSERT_TRUE(r.status.ok()) << angle << ": " << r.status.message;
    ASSERT_EQ(r.edges.size(), 1u) << angle;
    EXPECT_NEAR(r.edges[0].position, truth, 0.03) << angle;
    EXPECT_NEAR(r.edges[0].amplitude, 120, 6) << angle;  // rising: light beyond
    EXPECT_NEAR(r.edges[0].point.x, at.x, 0.03) << angle;
    EXPECT_NEAR(r.edges[0].point.y, at.y, 0.03) << angle;
    EXPECT_FALSE(r.partial);
  }
}

TEST(Caliper, IsUnbiasedWhetherTheBlurActsBeforeOrAfterThePixel) {
  // Noise-free: what remains is the estimator's own bias, for both image formations.
  double worstGrid = 0, worstLens = 0;
  for (int k = 0; k < 12; ++k) {
    const double angle = 7.0 + 29.0 * k, truth = -2.0 + 0.37 * k;
    const MeasuringRect rect{32.2, 31.7, 40, 20, angle};
    const cv::Point2d at = cv::Point2d(rect.cx, rect.cy) + truth * axisOf(angle);
    const cv::Point2d normal = axisOf(angle - 2.0);
    for (bool lens : {false, true}) {
      const cv::Mat image = lens ? test::lensEdgeImage({64, 64}, at, normal, 40, 190, 0.9)
                                 : test::gridEdgeImage({64, 64}, at, normal, 40, 190, 0.9);
      const CaliperResult r = measureCaliper(image, MeasuringPath(rect));
      ASSERT_TRUE(r.status.ok() && r.edges.size() == 1) << k << (lens ? " lens" : " grid");
      double& worst = lens ? worstLens : worstGrid;
      worst = std::max(worst, std::abs(r.edges[0].position - truth));
    }
  }
  EXPECT_LT(worstGrid, 0.015);
  EXPECT_LT(worstLens, 0.015);
}

// A light bar `width` px wide across the axis, its middle at `centre` on the axis.
// Light bars `width` px wide across the caliper, centred at `centres` along its axis.
cv::Mat barsImage(const MeasuringRect& rect, const std::vector<double>& centres, double width,
                  double dark, double light, double noise = 1.0, double blur = 0.9,
                  scene::BlurModel model = scene::BlurModel::PixelGrid, std::uint64_t seed = 1) {
  scene::SceneSpec spec;
  spec.size = {80, 80};
  spec.background = dark;
  spec.blurSigma = blur;
  spec.blurModel = model;
  spec.noiseSigma = noise;
  spec.subrows = 64;
  spec.seed = seed;
  scene::Scene s(spec);
  const cv::Point2d d = axisOf(rect.angle), t(-d.y, d.x);
  for (const double centre : centres) {
    const cv::Point2d m = cv::Point2d(rect.cx, rect.cy) + centre * d;
    const double h = width / 2, far = 100;
    s.addPolygon(
        {m - h * d - far * t, m + h * d - far * t, m + h * d + far * t, m - h * d + far * t},
        light);
  }
  return s.render();
}

cv::Mat barImage(const MeasuringRect& rect, double centre, double width, double dark, double light,
                 double noise = 1.0, double blur = 0.9,
                 scene::BlurModel model = scene::BlurModel::PixelGrid) {
  return barsImage(rect, {centre}, width, dark, light, noise, blur, model);
}

TEST(Caliper, PairsGiveTheWidthAndCentreOfABarFourPixelsWide) {
  const MeasuringRect rect{40.4, 39.8, 40, 20, 61.0};
  const cv::Mat image = barImage(rect, 1.3, 4.3, 60, 180);
  CaliperParams p;
  p.pairs = true;
  p.polarity = EdgePolarity::Rising;
  const CaliperResult r = measureCaliper(image, MeasuringPath(rect), p);
  ASSERT_TRUE(r.status.ok()) << r.status.message;
  ASSERT_EQ(r.pairs.size(), 1u);
  EXPECT_NEAR(r.pairs[0].width, 4.3, 0.04);
  EXPECT_NEAR(r.pairs[0].position, 1.3, 0.03);
  EXPECT_GT(r.pairs[0].first.amplitude, 0);
  EXPECT_LT(r.pairs[0].second.amplitude, 0);
  // A light bar has no falling-then-rising pair.
  p.polarity = EdgePolarity::Falling;
  const CaliperResult none = measureCaliper(image, MeasuringPath(rect), p);
  EXPECT_EQ(none.status.cause, MeasureFailure::NoPair);
}

// Bars narrower than about three blur widths: the two edges' blurs overlap, and each edge fitted
// alone saw the other's model error (a 4 px bar under blur 1.5 read 0.12 px too wide); fitted as
// one bar, noise-free, the width is right under both image formations. (At 3 px the width and the
// blur trade off: 8-bit rounding alone moves the width by up to 0.17 px there.)
TEST(Caliper, BarsNarrowerThanTheirBlurKeepTheirWidth) {
  CaliperParams p;
  p.pairs = true;
  double worstWidth = 0, worstCentre = 0;
  for (const auto model : {scene::BlurModel::PixelGrid, scene::BlurModel::Lens})
    for (const double width : {4.0, 5.0})
      for (int k = 0; k < 4; ++k) {
        const MeasuringRect rect{40.3, 39.6, 40, 20, 11.0 + 47.0 * k};
        const double centre = -0.6 + 0.37 * k;
        const cv::Mat image = barImage(rect, centre, width, 60, 170, 0.0, 1.5, model);
        const CaliperResult r = measureCaliper(image, MeasuringPath(rect), p);
        ASSERT_TRUE(r.status.ok()) << r.status.message;
        ASSERT_EQ(r.pairs.size(), 1u);
        worstWidth = std::max(worstWidth, std::abs(r.pairs[0].width - width));
        worstCentre = std::max(worstCentre, std::abs(r.pairs[0].position - centre));
        // The edges report the bar's positions too.
        ASSERT_EQ(r.edges.size(), 2u);
        EXPECT_DOUBLE_EQ(r.edges[1].position - r.edges[0].position, r.pairs[0].width);
      }
  EXPECT_LT(worstWidth, 0.05);
  EXPECT_LT(worstCentre, 0.03);
}

// Two bars of 4 px, 3 and 4 px apart, under a blur of 1.5 px (a comb whose pitch is under five
// blur widths): the single-edge fits of the inner edges degenerate (steps of thousands of grey
// levels, or none), the joint fit of the four edges keeps every edge and width.
TEST(Caliper, CombFinerThanItsBlurKeepsEveryEdge) {
  CaliperParams p;
  p.pairs = true;
  double worst = 0;
  for (const auto model : {scene::BlurModel::PixelGrid, scene::BlurModel::Lens})
    for (const double gap : {3.0, 4.0})
      for (int k = 0; k < 4; ++k) {
        const MeasuringRect rect{40.3, 39.6, 40, 20, 13.0 + 41.0 * k};
        const double c0 = -0.3 + 0.13 * k, half = 0.5 * (4.0 + gap);
        const cv::Mat image =
            barsImage(rect, {c0 - half, c0 + half}, 4.0, 60, 170, 0.0, 1.5, model);
        const CaliperResult r = measureCaliper(image, MeasuringPath(rect), p);
        ASSERT_TRUE(r.status.ok()) << r.status.message;
        ASSERT_EQ(r.edges.size(), 4u) << "gap " << gap << " angle " << rect.angle;
        ASSERT_EQ(r.pairs.size(), 2u);
        for (const CaliperEdge& e : r.edges) EXPECT_NEAR(std::abs(e.amplitude), 110.0, 5.0);
        for (int i = 0; i < 2; ++i) {
          worst = std::max(worst, std::abs(r.pairs[i].width - 4.0));
          worst = std::max(worst, std::abs(r.pairs[i].position - (c0 + (i ? half : -half))));
        }
      }
  EXPECT_LT(worst, 0.05);
}

// A comb of eight such teeth (sixteen crowded edges, more than one joint fit takes): fitted in
// blocks, every tooth is read.
TEST(Caliper, LongCombFinerThanItsBlurKeepsEveryTooth) {
  CaliperParams p;
  p.pairs = true;
  for (const auto model : {scene::BlurModel::PixelGrid, scene::BlurModel::Lens}) {
    const MeasuringRect rect{40.3, 39.6, 78, 20, 17.0};
    std::vector<double> centres;
    for (int k = 0; k < 8; ++k) centres.push_back(0.2 + 8.0 * (k - 3.5));
    const cv::Mat image = barsImage(rect, centres, 4.0, 60, 170, 0.0, 1.5, model);
    const CaliperResult r = measureCaliper(image, MeasuringPath(rect), p);
    ASSERT_TRUE(r.status.ok()) << r.status.message;
    ASSERT_EQ(r.edges.size(), 16u);
    ASSERT_EQ(r.pairs.size(), 8u);
    for (int k = 0; k < 8; ++k) {
      EXPECT_NEAR(r.pairs[k].width, 4.0, 0.1) << k;
      EXPECT_NEAR(r.pairs[k].position, centres[k], 0.05) << k;
    }
  }
}

// The same comb with noise: every edge and no other, none of them made up (a step no larger than
// the grey values span), on many noise draws.
TEST(Caliper, NoisyCombFinerThanItsBlurMakesUpNoEdge) {
  CaliperParams p;
  p.pairs = true;
  for (std::uint64_t seed = 1; seed <= 24; ++seed) {
    const MeasuringRect rect{40.3, 39.6, 40, 20, 7.0 * static_cast<double>(seed)};
    const double gap = seed % 2 ? 3.0 : 4.0, half = 0.5 * (4.0 + gap);
    const auto model = seed % 3 ? scene::BlurModel::Lens : scene::BlurModel::PixelGrid;
    const cv::Mat image = barsImage(rect, {-half, half}, 4.0, 60, 170, 2.0, 1.5, model, seed);
    const CaliperResult r = measureCaliper(image, MeasuringPath(rect), p);
    ASSERT_TRUE(r.status.ok()) << r.status.message;
    ASSERT_EQ(r.edges.size(), 4u) << "seed " << seed;
    ASSERT_EQ(r.pairs.size(), 2u) << "seed " << seed;
    for (const CaliperEdge& e : r.edges) EXPECT_LT(std::abs(e.amplitude), 140.0) << seed;
    for (const CaliperPair& pr : r.pairs) EXPECT_NEAR(pr.width, 4.0, 0.5) << seed;
  }
}

// Random combs (1-6 bars of 0.5-7.5 px and random greys, gaps 0.5-7.5 px, blur 0.4-3, noise
// 0-8, both blur models) under random calipers, partly outside the image at times: whatever the
// caliper reports is finite, in axis order, on the path, and no step is larger than the sensor's
// range could make -- many of these combs cannot be resolved, and then the caliper reports fewer
// edges or fails with a cause, never made-up ones.
TEST(Caliper, RandomCombsGiveNoMadeUpEdge) {
  std::mt19937_64 rng(20261129);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  int measured = 0;
  for (int it = 0; it < 120; ++it) {
    scene::SceneSpec spec;
    spec.size = {60, 60};
    spec.background = 20 + 200 * u(rng);
    spec.blurSigma = 0.4 + 2.6 * u(rng);
    spec.blurModel = u(rng) < 0.5 ? scene::BlurModel::Lens : scene::BlurModel::PixelGrid;
    spec.noiseSigma = 8 * u(rng) * u(rng);
    spec.subrows = 16;
    spec.seed = static_cast<std::uint64_t>(it) + 1;
    scene::Scene s(spec);
    const double angle = 360 * u(rng);
    const cv::Point2d d = axisOf(angle), t(-d.y, d.x);
    double at = -15 + 5 * u(rng);
    for (int bars = 1 + static_cast<int>(6 * u(rng)); bars > 0; --bars) {
      const double width = 0.5 + 7 * u(rng), gap = 0.5 + 7 * u(rng);
      const cv::Point2d a = cv::Point2d(30, 30) + at * d, b = a + width * d;
      s.addPolygon({a - 100 * t, b - 100 * t, b + 100 * t, a + 100 * t}, 255 * u(rng));
      at += width + gap;
    }
    const MeasuringRect rect{30 + 20 * (u(rng) - 0.5), 30 + 20 * (u(rng) - 0.5), 10 + 50 * u(rng),
                             2 + 20 * u(rng), angle + 6 * (u(rng) - 0.5)};
    CaliperParams p;
    p.pairs = u(rng) < 0.5;
    p.minAmplitude = 5 + 30 * u(rng);
    const CaliperResult r = measureCaliper(s.render(), MeasuringPath(rect), p);
    if (!r.status.ok()) {
      EXPECT_FALSE(r.status.message.empty()) << it;
      continue;
    }
    ++measured;
    for (std::size_t i = 0; i < r.edges.size(); ++i) {
      const CaliperEdge& e = r.edges[i];
      ASSERT_TRUE(std::isfinite(e.position) && std::isfinite(e.amplitude)) << it;
      EXPECT_LE(std::abs(e.position), rect.length / 2 + 1e-9) << it;
      EXPECT_LE(std::abs(e.amplitude), 1.2 * 255) << it;
      if (i > 0) {
        EXPECT_LT(r.edges[i - 1].position, e.position) << it;
      }
    }
  }
  EXPECT_GT(measured, 70);  // most of them do have edges
}

// A dark bar in a backlight 1.6 times the sensor's clip (it reads 255 on both sides): its edges
// are flagged as clipped (their positions lie up to a pixel towards the bar); a bar within the
// sensor's range is not flagged.
TEST(Caliper, EdgesBesideClippedGreyValuesAreFlagged) {
  CaliperParams p;
  p.pairs = true;
  p.polarity = EdgePolarity::Falling;
  const MeasuringRect rect{40.4, 39.8, 40, 20, 23.0};
  for (const double light : {400.0, 230.0}) {
    const CaliperResult r =
        measureCaliper(barImage(rect, -0.7, 8.3, light, 30, 2.0), MeasuringPath(rect), p);
    ASSERT_TRUE(r.status.ok()) << r.status.message;
    ASSERT_EQ(r.pairs.size(), 1u);
    EXPECT_EQ(r.pairs[0].first.clipped, light > 255) << light;
    EXPECT_EQ(r.pairs[0].second.clipped, light > 255) << light;
    if (light < 255) {
      EXPECT_NEAR(r.pairs[0].width, 8.3, 0.05);
    }
  }
}

TEST(Caliper, SelectsFirstLastStrongestOrAllOfAComb) {
  // Three teeth: the middle one has the most contrast.
  scene::SceneSpec spec;
  spec.size = {100, 40};
  spec.background = 50;
  spec.blurSigma = 0.9;
  spec.subrows = 64;
  scene::Scene s(spec);
  const double teeth[][2] = {{20.3, 120}, {45.7, 220}, {70.1, 120}};  // left x, grey
  for (const auto& [x, g] : teeth) s.addPolygon({{x, -5}, {x + 8, -5}, {x + 8, 45}, {x, 45}}, g);
  const cv::Mat image = s.render();
  const MeasuringPath path(MeasuringRect{49.5, 19.5, 90, 10, 0});
  CaliperParams p;
  CaliperResult all = measureCaliper(image, path, p);
  ASSERT_TRUE(all.status.ok());
  ASSERT_EQ(all.edges.size(), 6u);
  for (std::size_t i = 0; i < 6; ++i) {
    const double x = teeth[i / 2][0] + (i % 2 ? 8.0 : 0.0);
    // 0.03: the middle tooth's two edges both come out 0.022 px low, noise-free (not understood
    // yet; the isolated-edge tests hold 0.015).
    EXPECT_NEAR(all.edges[i].position, x - 49.5, 0.03) << i;
    EXPECT_EQ(all.edges[i].amplitude > 0, i % 2 == 0) << i;
  }
  p.select = EdgeSelect::First;
  EXPECT_NEAR(measureCaliper(image, path, p).edges.at(0).position, 20.3 - 49.5, 0.02);
  p.select = EdgeSelect::Last;
  EXPECT_NEAR(measureCaliper(image, path, p).edges.at(0).position, 78.1 - 49.5, 0.02);
  p.select = EdgeSelect::Strongest;
  p.polarity = EdgePolarity::Falling;
  EXPECT_NEAR(measureCaliper(image, path, p).edges.at(0).position, 53.7 - 49.5, 0.03);
  // Pairs of the comb: three teeth, each 8 px wide, spaced 25.4 and 24.4 px.
  p = {};
  p.pairs = true;
  const CaliperResult pairs = measureCaliper(image, path, p);
  ASSERT_EQ(pairs.pairs.size(), 3u);
  for (const CaliperPair& pr : pairs.pairs) EXPECT_NEAR(pr.width, 8.0, 0.02);
  EXPECT_NEAR(pairs.pairs[1].position - pairs.pairs[0].position, 25.4, 0.04);
}

TEST(Caliper, ArcMeasuresAlongTheArcLength) {
  // A half-plane whose boundary is a ray from the arc's centre at 50 degrees: along an arc of
  // radius 20 from 0 to 90 degrees the edge lies 5 degrees past the middle.
  const cv::Point2d c(40.2, 40.7);
  const cv::Point2d normal = axisOf(50.0 + 90.0);  // light on the counter-clockwise side
  const cv::Mat image = test::gridEdgeImage({80, 80}, c, normal, 40, 170, 0.9);
  const MeasuringArc arc{c.x, c.y, 20.0, 0.0, 90.0, 6.0};
  const CaliperResult r = measureCaliper(image, MeasuringPath(arc));
  ASSERT_TRUE(r.status.ok()) << r.status.message;
  ASSERT_EQ(r.edges.size(), 1u);
  EXPECT_NEAR(r.edges[0].position, 20.0 * 5.0 * CV_PI / 180.0, 0.03);
  EXPECT_GT(r.edges[0].amplitude, 0);  // dark to light going counter-clockwise
  const cv::Point2d expected = c + 20.0 * axisOf(50.0);
  EXPECT_NEAR(r.edges[0].point.x, expected.x, 0.05);
  EXPECT_NEAR(r.edges[0].point.y, expected.y, 0.05);
}

TEST(Caliper, MeasuresTheInsideOfARectanglePartlyOutsideAndSaysSo) {
  const cv::Mat image = test::gridEdgeImage({60, 60}, {50.4, 30}, {1, 0}, 40, 170, 0.9, 1.0);
  // The caliper runs from x = 30 to x = 70: the part beyond x = 59 is outside the image.
  const CaliperResult r = measureCaliper(image, MeasuringPath(MeasuringRect{50, 30, 40, 10, 0}));
  ASSERT_TRUE(r.status.ok()) << r.status.message;
  EXPECT_TRUE(r.partial);
  ASSERT_EQ(r.edges.size(), 1u);
  EXPECT_NEAR(r.edges[0].position, 0.4, 0.05);
}

TEST(Caliper, FailsWithItsCauseInsteadOfInventingAnEdge) {
  const cv::Mat edge = test::gridEdgeImage({60, 60}, {30.4, 30}, {1, 0}, 40, 170, 0.9, 1.0);
  const cv::Mat flat(60, 60, CV_8U, cv::Scalar(90));
  auto cause = [](const cv::Mat& im, MeasuringRect rect, CaliperParams p = {}) {
    return measureCaliper(im, MeasuringPath(rect), p).status.cause;
  };
  EXPECT_EQ(cause(edge, {200, 200, 40, 10, 0}), MeasureFailure::OutsideImage);
  EXPECT_EQ(cause(edge, {30, 30, 0, 10, 0}), MeasureFailure::ZeroSize);
  EXPECT_EQ(cause(edge, {30, 30, 40, 0, 0}), MeasureFailure::ZeroSize);
  EXPECT_EQ(cause(flat, {30, 30, 40, 10, 0}), MeasureFailure::NoContrast);
  CaliperParams falling;
  falling.polarity = EdgePolarity::Falling;
  EXPECT_EQ(cause(edge, {30, 30, 40, 10, 0}, falling), MeasureFailure::NoEdge);
  CaliperParams strong;
  strong.minAmplitude = 200;  // more than the 130 grey levels of the step
  EXPECT_EQ(cause(edge, {30, 30, 40, 10, 0}, strong), MeasureFailure::NoContrast);
  // The measuring axis along the edge sees no step.
  EXPECT_EQ(cause(edge, {45, 30, 20, 4, 90}), MeasureFailure::NoContrast);
}

TEST(Caliper, ReadsSixteenBitImagesOnTheEightBitScale) {
  const cv::Mat eight = test::gridEdgeImage({60, 60}, {31.2, 30}, {1, 0}, 40, 170, 0.9);
  cv::Mat sixteen;
  eight.convertTo(sixteen, CV_16U, 256.0);
  const MeasuringPath path(MeasuringRect{30, 30, 30, 10, 0});
  const CaliperResult a = measureCaliper(eight, path), b = measureCaliper(sixteen, path);
  ASSERT_TRUE(a.status.ok() && b.status.ok());
  EXPECT_NEAR(a.edges.at(0).position, b.edges.at(0).position, 1e-9);
  EXPECT_NEAR(a.edges.at(0).amplitude, b.edges.at(0).amplitude, 1e-6);
  cv::Mat colour;
  cv::merge(std::vector<cv::Mat>{eight, eight, eight}, colour);
  EXPECT_THROW(measureCaliper(colour, path), std::invalid_argument);
}

}  // namespace
}  // namespace facet
