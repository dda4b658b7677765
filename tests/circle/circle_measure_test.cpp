// CircleMeasure on generated scenes with exact ground truth: accuracy for both polarities, a ring
// measured as two concentric circles, partial arcs, every failure flag and bad input.
#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>

#include <gtest/gtest.h>

#include "algorithms/circle/circle_measure.hpp"
#include "algorithms/circle/circle_profile_fit.hpp"
#include "algorithms/circle/rim_ellipse.hpp"
#include "tests/support/scene/plane_scene.hpp"
#include "tests/support/scene/scene.hpp"

namespace facet {
namespace {

using scene::Scene;
using scene::SceneSpec;

SceneSpec spec(int side, double background, int depth = CV_8U) {
  SceneSpec s;
  s.size = {side, side};
  s.background = background;
  s.blurSigma = 1.0;
  s.noiseSigma = 2.0;
  s.depth = depth;
  s.subrows = 64;
  return s;
}

CircleMeasureParams params(cv::Point2d centre, double radius, CirclePolarity polarity) {
  CircleMeasureParams p;
  p.centre = centre;
  p.radius = radius;
  p.polarity = polarity;
  return p;
}

void expectCircle(const CircleMeasurement& m, cv::Point2d centre, double radius, double tol) {
  ASSERT_TRUE(m.status.ok()) << m.status.message;
  EXPECT_NEAR(m.centre.x, centre.x, tol);
  EXPECT_NEAR(m.centre.y, centre.y, tol);
  EXPECT_NEAR(m.radius, radius, tol);
  EXPECT_NEAR(m.diameter, 2 * radius, 2 * tol);
  EXPECT_LT(m.rms, 0.2);
  EXPECT_GT(m.coverageDeg, 350.0);
  EXPECT_EQ(static_cast<std::size_t>(m.inliers), m.inlierPoints.size());
  EXPECT_GE(m.roundness, 0.0);
  EXPECT_LT(m.roundness, 1.0);
  EXPECT_FALSE(m.elliptic);  // a round rim is no ellipse
  EXPECT_EQ(m.majorDiameter, m.diameter);
  EXPECT_EQ(m.minorDiameter, m.diameter);
}

// The outline of an ellipse (720 vertices: within 0.001 px of it) with semi-axes a and b, the
// major one `angleDeg` degrees below the image's x axis (y down).
std::vector<cv::Point2d> ellipseOutline(cv::Point2d c, double a, double b, double angleDeg) {
  const double t = angleDeg * std::numbers::pi / 180.0;
  std::vector<cv::Point2d> outline;
  for (int i = 0; i < 720; ++i) {
    const double s = 2 * std::numbers::pi * i / 720;
    const double u = a * std::cos(s), v = b * std::sin(s);
    outline.push_back(
        {c.x + u * std::cos(t) - v * std::sin(t), c.y + u * std::sin(t) + v * std::cos(t)});
  }
  return outline;
}

TEST(CircleMeasure, LightDiscAtSubpixelCentresFromAnOffsetStart) {
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (double radius : {12.3, 37.8, 80.4}) {
    const int side = static_cast<int>(2 * radius + 40);
    Scene s(spec(side, 60));
    const cv::Point2d c{side / 2.0 + u(rng), side / 2.0 - u(rng)};
    s.addDisc(c, radius, 160);
    const auto m = measureCircle(s.render(), params(c + cv::Point2d(1.5, -1.0), std::round(radius),
                                                    CirclePolarity::LightToDark));
    SCOPED_TRACE(radius);
    expectCircle(m, c, radius, 0.05);
  }
}

TEST(CircleMeasure, DarkHoleAndPolarityIsRespected) {
  Scene s(spec(140, 170));
  const cv::Point2d c{70.31, 68.77};
  s.addDisc(c, 40.2, 60, "hole");
  const cv::Mat image = s.render();
  expectCircle(measureCircle(image, params({71, 68}, 40, CirclePolarity::DarkToLight)), c, 40.2,
               0.05);
  expectCircle(measureCircle(image, params({71, 68}, 40, CirclePolarity::Any)), c, 40.2, 0.05);
  // The wrong polarity finds no rim: a flag, not a circle.
  const auto wrong = measureCircle(image, params({71, 68}, 40, CirclePolarity::LightToDark));
  EXPECT_FALSE(wrong.status.ok());
  EXPECT_EQ(wrong.status.cause, CircleFailure::TooFewPoints) << wrong.status.message;
  EXPECT_TRUE(std::isnan(wrong.radius));
  EXPECT_TRUE(std::isnan(wrong.centre.x));
}

TEST(CircleMeasure, RingIsTwoConcentricMeasurementsWithOppositePolarity) {
  // A light washer (outer radius 50) with a dark bore (radius 25) on a dark background.
  Scene s(spec(150, 50));
  const cv::Point2d c{74.6, 75.2};
  s.addDisc(c, 50.4, 180);
  s.addDisc(c, 25.3, 50, "hole");
  const cv::Mat image = s.render();
  const auto outer = measureCircle(image, params({75, 75}, 50, CirclePolarity::LightToDark));
  const auto inner = measureCircle(image, params({75, 75}, 25, CirclePolarity::DarkToLight));
  expectCircle(outer, c, 50.4, 0.05);
  expectCircle(inner, c, 25.3, 0.05);
  EXPECT_NEAR(outer.centre.x, inner.centre.x, 0.05);
  EXPECT_NEAR(outer.centre.y, inner.centre.y, 0.05);
}

TEST(CircleMeasure, SixteenBitImage) {
  Scene s(spec(120, 60, CV_16U));
  const cv::Point2d c{60.2, 59.6};
  s.addDisc(c, 30.7, 160);
  const cv::Mat image = s.render();
  ASSERT_EQ(image.depth(), CV_16U);
  expectCircle(measureCircle(image, params({61, 59}, 31, CirclePolarity::LightToDark)), c, 30.7,
               0.05);
}

// A disc whose right part is cut away by a straight edge: only an arc of the rim remains.
cv::Mat partialDisc(cv::Point2d c, double radius, double keepDeg) {
  Scene s(spec(160, 60));
  s.addDisc(c, radius, 160);
  // The occluding half-plane starts where the kept arc ends (arc symmetric about the left).
  const double x = c.x + radius * std::cos((180.0 - keepDeg / 2.0) * std::numbers::pi / 180.0);
  s.addPolygon({{x, -10}, {200, -10}, {200, 200}, {x, 200}}, 60, "occluder");
  return s.render();
}

TEST(CircleMeasure, PartialArcWithMinimumCoverage) {
  const cv::Point2d c{90.4, 80.3};
  const cv::Mat image = partialDisc(c, 50.2, 140);
  auto p = params({90, 80}, 50, CirclePolarity::LightToDark);
  p.minCoverageDeg = 100;
  const auto m = measureCircle(image, p);
  ASSERT_TRUE(m.status.ok()) << m.status.message;
  EXPECT_NEAR(m.centre.x, c.x, 0.1);
  EXPECT_NEAR(m.centre.y, c.y, 0.1);
  EXPECT_NEAR(m.radius, 50.2, 0.1);
  EXPECT_GT(m.coverageDeg, 115.0);
  EXPECT_LT(m.coverageDeg, 150.0);
}

TEST(CircleMeasure, CoverageTooSmallIsAFlag) {
  const cv::Mat image = partialDisc({90.4, 80.3}, 50.2, 100);
  auto p = params({90, 80}, 50, CirclePolarity::LightToDark);
  p.minCoverageDeg = 180;
  const auto m = measureCircle(image, p);
  EXPECT_FALSE(m.status.ok());
  EXPECT_EQ(m.status.cause, CircleFailure::CoverageTooSmall) << m.status.message;
  EXPECT_EQ(toString(m.status.cause), "coverage_too_small");
  EXPECT_LT(m.coverageDeg, 180.0);
  EXPECT_GT(m.coverageDeg, 60.0);
  EXPECT_TRUE(std::isnan(m.radius));
}

TEST(CircleMeasure, TooFewPointsOnAFlatImage) {
  Scene s(spec(100, 90));
  const auto m = measureCircle(s.render(), params({50, 50}, 20, CirclePolarity::Any));
  EXPECT_FALSE(m.status.ok());
  EXPECT_EQ(m.status.cause, CircleFailure::TooFewPoints) << m.status.message;
  EXPECT_EQ(toString(m.status.cause), "too_few_points");
  EXPECT_TRUE(std::isnan(m.centre.x));
}

TEST(CircleMeasure, FitTooPoorOnAWavyRim) {
  // A 12-sided rim with rounded-off detail: the edge points lie on a star, not a circle; with a
  // tight rms limit the fit is rejected as too poor rather than reported.
  Scene s(spec(140, 60));
  std::vector<cv::Point2d> star;
  const cv::Point2d c{70, 70};
  for (int i = 0; i < 72; ++i) {
    const double a = 2 * std::numbers::pi * i / 72;
    const double r = 40 + 1.2 * std::sin(12 * a);
    star.push_back({c.x + r * std::cos(a), c.y + r * std::sin(a)});
  }
  s.addPolygon(star, 170);
  const cv::Mat image = s.render();
  auto p = params(c, 40, CirclePolarity::LightToDark);
  p.ransacThreshold = 2.0;  // accept the wavy rim as one circle ...
  p.robustWeight = CircleRobustWeight::None;
  p.maxRms = 0.3;  // ... but not its residuals
  const auto m = measureCircle(image, p);
  EXPECT_FALSE(m.status.ok());
  EXPECT_EQ(m.status.cause, CircleFailure::FitTooPoor) << m.status.message;
  EXPECT_EQ(toString(m.status.cause), "fit_too_poor");
  EXPECT_GT(m.rms, 0.3);
  EXPECT_GT(m.roundness, 1.5);  // the wave's peak to peak is 2.4 px
  // A generous limit accepts the same rim and reports its roundness.
  p.maxRms = 2.0;
  const auto loose = measureCircle(image, p);
  ASSERT_TRUE(loose.status.ok()) << loose.status.message;
  EXPECT_GT(loose.roundness, 1.5);
  EXPECT_LT(loose.roundness, 3.5);
}

// A hole of radius 30 px on a plane viewed at a tilt of about 26 degrees: an ellipse with axes
// 30 and 27 px, the major one 25 degrees clockwise on screen, about `c`; with `hidden`, a strip
// over a third of it.
cv::Mat tiltedHole(cv::Point2d c, bool hidden) {
  Scene s(spec(120, 190));
  s.addPolygon(ellipseOutline(c, 30.0, 27.0, 25.0), 60.0);
  if (hidden) s.addPolygon({{0, 0}, {c.x - 12, 0}, {c.x - 12, 120}, {0, 120}}, 130.0, "occluder");
  return s.render();
}

// The tilted hole measured as its ellipse, centre within `tolerance` px.
void expectTheTiltedHole(const CircleMeasurement& m, cv::Point2d c, double tolerance) {
  ASSERT_TRUE(m.status.ok()) << m.status.message;
  EXPECT_TRUE(m.elliptic);
  EXPECT_TRUE(m.greyRefined);
  EXPECT_NEAR(m.centre.x, c.x, tolerance);
  EXPECT_NEAR(m.centre.y, c.y, tolerance);
  EXPECT_NEAR(m.majorDiameter, 60.0, 0.1);
  EXPECT_NEAR(m.minorDiameter, 54.0, 0.1);
  EXPECT_NEAR(m.majorAxisDeg, 155.0, 0.5);  // 25 degrees clockwise on screen
}

// The circle model (measureEllipticRims off) on the tilted hole: refused, or off the centre.
void expectTheCircleModelOff(const cv::Mat& image, CircleMeasureParams p, cv::Point2d c) {
  p.measureEllipticRims = false;
  const auto round = measureCircle(image, p);
  if (round.status.ok()) {
    EXPECT_FALSE(round.elliptic);
    EXPECT_GT(std::hypot(round.centre.x - c.x, round.centre.y - c.y), 0.3);
  }
}

TEST(CircleMeasure, AnEllipticRimIsMeasuredAsItsEllipse) {
  // A circle's 0.5 px band keeps the arcs of this rim that one circle matches, on one side.
  const cv::Point2d c{60.37, 58.81};
  const cv::Mat image = tiltedHole(c, false);
  const auto p = params(c + cv::Point2d(1.0, -0.7), 28.5, CirclePolarity::DarkToLight);
  const auto m = measureCircle(image, p);
  expectTheTiltedHole(m, c, 0.02);
  EXPECT_NEAR(m.radius, std::sqrt(30.0 * 27.0), 0.05);  // the circle of the ellipse's area
  EXPECT_NEAR(m.roundness, 3.0, 0.3);                   // the axes' difference
  EXPECT_LT(m.rms, 0.1);                                // from the ellipse
  EXPECT_GT(m.coverageDeg, 350.0);
  // As a circle, the same rim's centre is off by a pixel or more along the minor axis.
  expectTheCircleModelOff(image, p, c);
}

TEST(CircleMeasure, AnEllipticRimWithASectorHiddenIsMeasuredAsItsEllipse) {
  // The tilted hole with a strip over a third of it. The edge points' ellipse covers too little
  // of the rim to be accepted on their word (300 degrees), a circle through the arcs it matches
  // is pixels off; the circle's grey-value fit finds the second harmonic, and the ellipse
  // refined in the grey values is the rim.
  const cv::Point2d c{60.37, 58.81};
  const cv::Mat image = tiltedHole(c, true);
  const auto p = params(c + cv::Point2d(1.0, -0.7), 28.5, CirclePolarity::DarkToLight);
  const auto m = measureCircle(image, p);
  expectTheTiltedHole(m, c, 0.03);
  EXPECT_LT(m.coverageDeg, 300.0);
  expectTheCircleModelOff(image, p, c);
}

TEST(CircleMeasure, ASlightlyEllipticRimKeepsItsGreyValueFitOnTheCentre) {
  // Axes 0.6 px apart (a tilt of about 11 degrees at r = 30): every edge point lies within the
  // circle's band, but the grey-value fit of a circle does not fit the rim (its sector screen
  // drops the sectors the circle misses most), and moves the centre.
  Scene s(spec(120, 60));
  const cv::Point2d c{59.62, 60.27};
  s.addPolygon(ellipseOutline(c, 30.3, 29.7, -40.0), 170.0);
  const cv::Mat image = s.render();
  const auto m = measureCircle(image, params(c, 30.0, CirclePolarity::LightToDark));
  ASSERT_TRUE(m.status.ok()) << m.status.message;
  EXPECT_TRUE(m.elliptic);
  EXPECT_TRUE(m.greyRefined);
  EXPECT_NEAR(m.centre.x, c.x, 0.01);
  EXPECT_NEAR(m.centre.y, c.y, 0.01);
  EXPECT_NEAR(m.majorDiameter - m.minorDiameter, 1.2, 0.1);
  EXPECT_NEAR(m.majorAxisDeg, 40.0, 3.0);
}

TEST(CircleProfileFit, ItsSecondHarmonicTellsAnEllipseAndItsStepReachesIt) {
  // The grey-value fit of a circle, asked to judge the rim's shape: on a round rim the harmonic's
  // chi-square stays within chance; on a rim of axes 20.2 and 19.8 px it is far beyond, and the
  // ellipse of its one step has the rim's stretch within a fifth (the measurement repeats the
  // step until it settles) and its axis within 3 degrees.
  const cv::Point2d c{40.31, 39.77};
  std::vector<cv::Point2d> rim;
  for (int i = 0; i < 72; ++i)
    rim.push_back(c + 20.0 * cv::Point2d(std::cos(i * std::numbers::pi / 36),
                                         std::sin(i * std::numbers::pi / 36)));
  SceneSpec sp = spec(80, 60);
  Scene round(sp), oval(sp);
  round.addDisc(c, 20.0, 170.0);
  oval.addPolygon(ellipseOutline(c, 20.2, 19.8, 30.0), 170.0);
  const auto r = fitCircleProfile(round.render(), c + cv::Point2d(0.3, -0.2), 20.0, rim, {}, 2.0,
                                  1.0, cv::Matx22d::eye(), true);
  const auto o = fitCircleProfile(oval.render(), c + cv::Point2d(0.3, -0.2), 20.0, rim, {}, 2.0,
                                  1.0, cv::Matx22d::eye(), true);
  ASSERT_TRUE(r && o);
  EXPECT_LT(r->secondHarmonic, 27.6);
  EXPECT_GT(o->secondHarmonic, 100.0);
  const rim_ellipse::Ellipse stepped =
      rim_ellipse::reshaped({{o->centre.x, o->centre.y}, o->radius, o->radius, {1.0, 0.0}},
                            o->shapeStep[0], o->shapeStep[1]);
  const double stretch = 0.5 * std::log(20.2 / 19.8);
  EXPECT_NEAR(0.5 * std::log(stepped.major / stepped.minor), stretch, 0.2 * stretch);
  const double deg = std::atan2(stepped.axis.y(), stepped.axis.x()) * 180.0 / std::numbers::pi;
  EXPECT_NEAR(std::remainder(deg - 30.0, 180.0), 0.0, 3.0);
  // Not asked: not computed.
  const auto plain = fitCircleProfile(oval.render(), c, 20.0, rim, {}, 2.0);
  ASSERT_TRUE(plain);
  EXPECT_TRUE(std::isnan(plain->secondHarmonic));
}

TEST(CircleMeasure, BadInputIsAFlagWithAClearMessage) {
  Scene s(spec(100, 60));
  s.addDisc({50, 50}, 20, 160);
  const cv::Mat image = s.render();
  const auto p = params({50, 50}, 20, CirclePolarity::Any);

  const auto empty = measureCircle(cv::Mat(), p);
  EXPECT_EQ(empty.status.cause, CircleFailure::BadInput);
  EXPECT_NE(empty.status.message.find("empty"), std::string::npos) << empty.status.message;

  cv::Mat colour;
  cv::Mat channels[] = {image, image, image};
  cv::merge(channels, 3, colour);
  const auto wrongType = measureCircle(colour, p);
  EXPECT_EQ(wrongType.status.cause, CircleFailure::BadInput);
  EXPECT_NE(wrongType.status.message.find("single-channel"), std::string::npos)
      << wrongType.status.message;
  cv::Mat floating;
  image.convertTo(floating, CV_32F);
  EXPECT_EQ(measureCircle(floating, p).status.cause, CircleFailure::BadInput);

  auto zero = p;
  zero.radius = 0;
  const auto r0 = measureCircle(image, zero);
  EXPECT_EQ(r0.status.cause, CircleFailure::BadInput);
  EXPECT_NE(r0.status.message.find("radius"), std::string::npos) << r0.status.message;
  EXPECT_EQ(toString(r0.status.cause), "bad_input");

  auto nan = p;
  nan.centre.x = std::nan("");
  EXPECT_EQ(measureCircle(image, nan).status.cause, CircleFailure::BadInput);

  auto outside = p;
  outside.centre = {400, -300};
  const auto out = measureCircle(image, outside);
  EXPECT_EQ(out.status.cause, CircleFailure::AnnulusOutsideImage) << out.status.message;
  EXPECT_EQ(toString(out.status.cause), "annulus_outside_image");
  EXPECT_NE(out.status.message.find("outside"), std::string::npos) << out.status.message;
  EXPECT_TRUE(std::isnan(out.radius));
}

TEST(CircleMeasure, ClutterAndOcclusionDoNotPullTheFit) {
  SceneSpec sp = spec(200, 60);
  sp.illuminationGradient = {0.2, -0.15};
  Scene s(sp);
  const cv::Point2d c{100.3, 99.6};
  s.addDisc(c, 60.2, 170);
  s.addDisc({c.x + 60, c.y}, 3, 250, "clutter");
  s.addDisc({c.x, c.y - 59}, 2.5, 20, "clutter");
  s.addOccluder({c.x - 60.2, c.y - 60.2, 120.4, 120.4}, 0.206, 120);
  const auto m = measureCircle(s.render(), params({101, 98.5}, 60, CirclePolarity::LightToDark));
  ASSERT_TRUE(m.status.ok()) << m.status.message;
  EXPECT_NEAR(m.centre.x, c.x, 0.05);
  EXPECT_NEAR(m.centre.y, c.y, 0.05);
  EXPECT_NEAR(m.radius, 60.2, 0.05);
  EXPECT_LT(m.coverageDeg, 290.0);
  EXPECT_GT(m.coverageDeg, 200.0);
}

}  // namespace
}  // namespace facet

namespace facet {
namespace {

TEST(CircleMeasure, GreyValueRefinementReportsTheBlurAndEdgeOnlyFitIsBiasCorrected) {
  Scene s(spec(120, 60));
  const cv::Point2d c{60.35, 59.8};
  s.addDisc(c, 20.4, 160);
  const cv::Mat image = s.render();
  auto p = params({61, 59}, 20, CirclePolarity::LightToDark);
  const auto refined = measureCircle(image, p);
  ASSERT_TRUE(refined.status.ok()) << refined.status.message;
  EXPECT_TRUE(refined.greyRefined);
  // PSF sigma 1 combined with the pixel's own width: sqrt(1 + 1/12) = 1.04.
  EXPECT_NEAR(refined.blur, 1.04, 0.15);
  expectCircle(refined, c, 20.4, 0.03);

  p.refineWithGreyValues = false;
  const auto edgeOnly = measureCircle(image, p);
  ASSERT_TRUE(edgeOnly.status.ok()) << edgeOnly.status.message;
  EXPECT_FALSE(edgeOnly.greyRefined);
  expectCircle(edgeOnly, c, 20.4, 0.05);
  // Without the curvature-bias correction the radius comes out about k / r = 0.05 px short.
  p.correctRadiusBias = false;
  const auto biased = measureCircle(image, p);
  ASSERT_TRUE(biased.status.ok()) << biased.status.message;
  EXPECT_LT(biased.radius, edgeOnly.radius - 0.03);
}

TEST(CircleMeasure, CircleCutByTheImageBorderIsAPartialArc) {
  Scene s(spec(100, 60));
  const cv::Point2d c{12.4, 50.3};  // 30 px radius: the left third lies outside the image
  s.addDisc(c, 30.2, 170);
  auto p = params({13, 50}, 30, CirclePolarity::LightToDark);
  const auto m = measureCircle(s.render(), p);
  ASSERT_TRUE(m.status.ok()) << m.status.message;
  EXPECT_NEAR(m.centre.x, c.x, 0.1);
  EXPECT_NEAR(m.centre.y, c.y, 0.1);
  EXPECT_NEAR(m.radius, 30.2, 0.1);
  EXPECT_LT(m.coverageDeg, 250.0);
  EXPECT_GT(m.coverageDeg, 150.0);
}

// An occluding strip hides 30% of a small rim and its far border, a straight edge of the rim's
// polarity, runs 2 px outside the hidden sector; blobs next to the rim pull a few true edge points
// off it. A circle through the border and the visible rim then fits almost as many edge points at
// the RANSAC threshold as the true one, but their gradients fan away from its radials. The wrong
// circle wins only now and then (here once in 160 scenes, 1.3 px off, without the radial test in
// RANSAC), hence the many scenes; they are the bench's hard case at r = 10. Large dark blobs
// inside the rim must not drag the grey-value fit either (one scene measured 0.15 px too large a
// radius while that fit's first step was unweighted).
TEST(CircleMeasure, StraightBorderBesideAnOccludedSectorDoesNotMakeACircle) {
  std::mt19937_64 rng(48);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  double worst = 0.0;
  for (int trial = 0; trial < 160; ++trial) {
    SceneSpec sp = spec(80, 70);
    sp.seed = rng();
    Scene s(sp);
    const cv::Point2d c{39.5 + u(rng) - 0.5, 39.5 + u(rng) - 0.5};
    const double radius = 9.7 + 0.6 * u(rng);
    s.addDisc(c, radius, 170);
    for (int k = 0; k < 3; ++k) {  // blobs 3 to 4.5 px off the rim, at least 1.5 px clear of it
      const double a = 2 * std::numbers::pi * u(rng);
      const double off = (u(rng) < 0.5 ? -1.0 : 1.0) * (3.0 + 1.5 * u(rng));
      const double grey = 255.0 * u(rng);
      const double blob = 0.7 + (std::abs(off) - 2.2) * u(rng);
      s.addDisc(c + (radius + off) * cv::Point2d(std::cos(a), std::sin(a)), blob, grey, "clutter");
    }
    s.addOccluder({c.x - radius, c.y - radius, 2 * radius, 2 * radius}, 0.206,
                  100.0 + 60.0 * u(rng));
    const double a = 2 * std::numbers::pi * u(rng);
    const auto m = measureCircle(s.render(), params(c + 1.8 * cv::Point2d(std::cos(a), std::sin(a)),
                                                    10, CirclePolarity::LightToDark));
    ASSERT_TRUE(m.status.ok()) << "trial " << trial << ": " << m.status.message;
    worst = std::max(worst, std::hypot(m.centre.x - c.x, m.centre.y - c.y));
    worst = std::max(worst, std::abs(m.radius - radius));
  }
  EXPECT_LT(worst, 0.1);
}

// The spec of one scene of bench_circle's hard case at r = 10, from its noise seed and ramp: the
// tests below rebuild scenes that the bench found measured wrong.
SceneSpec hardSceneSpec(std::uint64_t seed, cv::Point2d ramp) {
  SceneSpec sp = spec(80, 70);
  sp.subrows = 256;
  sp.seed = seed;
  sp.illuminationGradient = ramp;
  return sp;
}

// An occluder about as light as the disc hides the bottom of a small rim; its far side, a
// straight edge 2 px outside the rim, has the rim's polarity and a radial gradient near the
// bottom. Five of its points lie within the RANSAC threshold of a circle 1 px too low and too
// large, which also keeps its other inliers, and the grey-value fit cannot move that far: the
// measurement came out 1.17 px off and was reported as good (one scene in about 1,000 of the
// bench's hard case at r = 10; this is that scene). Judged against the rest of the rim, the
// run of five points lies 2 px off it and is dropped.
TEST(CircleMeasure, StraightEdgeRunThatTheRestOfTheRimDisagreesWithIsDropped) {
  Scene s(hardSceneSpec(3345750974238663308ull, {-0.657490, 0.360842}));
  const cv::Point2d c{39.1317, 39.8413};
  const double radius = 9.7527;
  s.addDisc(c, radius, 170);
  s.addPolygon({{19.9755, 19.9287}, {17.4964, 23.2475}, {14.7285, 19.4585}}, 54.855, "clutter");
  s.addDisc({48.1302, 63.9130}, 2.8584, 190.554, "clutter");
  s.addDisc({45.2735, 38.5991}, 1.6553, 7.383, "clutter");
  s.addDisc({51.3515, 34.5844}, 0.9992, 14.817, "clutter");
  s.addDisc({33.2801, 41.7601}, 1.9873, 61.931, "clutter");
  s.addPolygon({{27.3791, 45.5759}, {50.8844, 45.5759}, {50.8844, 51.5940}, {27.3791, 51.5940}},
               155.229, "occluder");
  const auto m =
      measureCircle(s.render(), params({39.6284, 40.8234}, 10, CirclePolarity::LightToDark));
  ASSERT_TRUE(m.status.ok()) << m.status.message;
  EXPECT_NEAR(m.centre.x, c.x, 0.1);
  EXPECT_NEAR(m.centre.y, c.y, 0.1);
  EXPECT_NEAR(m.radius, radius, 0.1);
  // No inlier on the occluder's far side (y about 51.6).
  for (const auto& p : m.inlierPoints) EXPECT_LT(p.y, 50.5);
}

// Clutter pulls the edge points' circle (inlier rms 0.12 px) until the clean arc from -150 to
// +50 degrees falls out of the inliers; the grey-value fit, which uses only the sectors the
// inliers cover, then had 140 of the rim's 250 unoccluded degrees and missed the centre by
// 0.12 px and the radius by 0.09 px. Its result re-collects that arc, and the fit is repeated.
TEST(CircleMeasure, CleanArcThatClutterPushedOutOfTheInliersReturnsToTheGreyValueFit) {
  Scene s(hardSceneSpec(3314388346836275554ull, {-0.544751, 0.515506}));
  const cv::Point2d c{39.5244, 39.1372};
  const double radius = 9.7945;
  s.addDisc(c, radius, 170);
  s.addDisc({56.0516, 3.9114}, 2.8195, 121.125, "clutter");
  s.addPolygon({{51.3035, 70.7993}, {53.2142, 69.0864}, {54.9493, 70.6491}, {53.4242, 72.4279}},
               130.855, "clutter");
  s.addPolygon({{46.0172, 1.6495}, {47.5224, 4.0471}, {44.2428, 4.0684}}, 12.554, "clutter");
  s.addPolygon({{72.4718, 27.8101}, {69.1008, 31.6230}, {68.1678, 26.0854}}, 1.127, "clutter");
  s.addPolygon({{46.4823, 5.6794}, {43.4771, 3.9099}, {46.9606, 2.3012}}, 81.102, "clutter");
  s.addDisc({21.3773, 53.9773}, 3.3130, 198.479, "clutter");
  s.addDisc({33.6126, 42.3038}, 1.5273, 238.043, "clutter");
  s.addDisc({28.4334, 30.1833}, 1.1130, 188.666, "clutter");
  s.addDisc({42.9900, 44.2882}, 1.7744, 43.091, "clutter");
  s.addPolygon({{27.7299, 27.3427}, {51.3190, 27.3427}, {51.3190, 33.3780}, {27.7299, 33.3780}},
               102.631, "occluder");
  const auto m =
      measureCircle(s.render(), params({39.1012, 39.0085}, 10, CirclePolarity::LightToDark));
  ASSERT_TRUE(m.status.ok()) << m.status.message;
  ASSERT_TRUE(m.greyRefined);
  EXPECT_LT(std::hypot(m.centre.x - c.x, m.centre.y - c.y), 0.05);
  EXPECT_NEAR(m.radius, radius, 0.04);
}

// Clutter blobs 1.5 to 2 px clear of a small rim, 75 to 90 grey levels off their surroundings:
// pixels near their detected edges stay out of the grey-value fit, but the blur carries a few grey
// levels of their contrast onto the rim pixels of their sectors, which no single pixel's Tukey
// weight notices. Those sectors' residuals stand out, and the sectors leave the fit (without that
// step the centre RMS here is about 0.026 px).
TEST(CircleMeasure, ClutterBlobsNextToASmallRimLeaveTheGreyValueFit) {
  std::mt19937_64 rng(14);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  double sum2 = 0.0;
  const int trials = 16;
  for (int trial = 0; trial < trials; ++trial) {
    SceneSpec sp = spec(80, 70);
    sp.seed = rng();
    Scene s(sp);
    const cv::Point2d c{39.5 + u(rng) - 0.5, 39.5 + u(rng) - 0.5};
    s.addDisc(c, 10.0, 170);
    // Blob: distance of its centre from the rim (negative: inside), its radius, its grey.
    const double blobs[3][3] = {{-4.4, 2.8, 244}, {3.3, 1.35, 159}, {4.4, 1.65, 160}};
    for (int k = 0; k < 3; ++k) {
      const double a = 2 * std::numbers::pi * (k + 0.3 * u(rng)) / 3.0;
      s.addDisc(c + (10.0 + blobs[k][0]) * cv::Point2d(std::cos(a), std::sin(a)), blobs[k][1],
                blobs[k][2], "clutter");
    }
    const auto m = measureCircle(s.render(), params({39.5, 39.5}, 10, CirclePolarity::LightToDark));
    ASSERT_TRUE(m.status.ok()) << "trial " << trial << ": " << m.status.message;
    ASSERT_TRUE(m.greyRefined);
    sum2 += std::pow(m.centre.x - c.x, 2) + std::pow(m.centre.y - c.y, 2);
  }
  const double rms = std::sqrt(sum2 / trials);
  EXPECT_LT(rms, 0.02);
}

// Clutter beyond the annulus of the edge points but inside the grey-value band: no edge point
// flags it, only its own gradient. Its blurred tails must leave the fit, and take no more of the
// rim's information than their own pixels: the same scenes without the blobs are the reference.
TEST(CircleMeasure, ClutterOutsideTheEdgeAnnulusCostsOnlyItsOwnPixels) {
  std::mt19937_64 rng(21);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  double sum2 = 0.0, clean2 = 0.0;
  const int trials = 24;
  for (int trial = 0; trial < trials; ++trial) {
    SceneSpec sp = spec(80, 70);
    sp.seed = rng();
    const cv::Point2d c{39.5 + u(rng) - 0.5, 39.5 + u(rng) - 0.5};
    Scene clean(sp), cluttered(sp);
    clean.addDisc(c, 10.0, 170);
    cluttered.addDisc(c, 10.0, 170);
    for (int k = 0; k < 3; ++k) {
      const double a = 2 * std::numbers::pi * (k + 0.3 * u(rng)) / 3.0;
      cluttered.addDisc(c + 15.5 * cv::Point2d(std::cos(a), std::sin(a)), 1.5, 250, "clutter");
    }
    auto p = params({39.5, 39.5}, 10, CirclePolarity::LightToDark);
    p.width = 3.0;  // the edge points' annulus ends 3 px outside the rim, the band 8 px
    const auto m = measureCircle(cluttered.render(), p);
    const auto k = measureCircle(clean.render(), p);
    ASSERT_TRUE(m.status.ok() && k.status.ok())
        << "trial " << trial << ": " << m.status.message << k.status.message;
    sum2 += std::pow(m.centre.x - c.x, 2) + std::pow(m.centre.y - c.y, 2);
    clean2 += std::pow(k.centre.x - c.x, 2) + std::pow(k.centre.y - c.y, 2);
  }
  const double rms = std::sqrt(sum2 / trials), cleanRms = std::sqrt(clean2 / trials);
  // Before the gradient screen the blobs' tails cost 19% here (0.0154 px against 0.0129).
  EXPECT_LT(rms, 1.05 * cleanRms);
  EXPECT_LT(rms, 0.02);
}

// A sharp image: a dark disc of radius 17.5 px seen square-on with exact pixel coverage and no
// lens blur (the pixel's box alone), noise 0.5, at ten subpixel places, measured from a nominal
// radius 2.5 px too large and from the right one. The Gaussian profile misfits such a step by
// several grey levels and the gradient screen took the rim's own aliased gradient for a foreign
// one: centres came out 0.28 px RMS off, up to 0.55. With the pixel's area in the model and the
// screen allowing the rim's Sobel turn: 0.002 px RMS (measured), either start.
TEST(CircleMeasure, ASharpDiscAtHighContrastIsMeasuredWithThePixelsArea) {
  double sum2 = 0;
  int n = 0;
  for (int seed = 1; seed <= 10; ++seed) {
    scene::PlaneScene s;
    s.camera.size = {400, 400};
    s.camera.fx = s.camera.fy = 1000, s.camera.cx = 199.5, s.camera.cy = 199.5;
    s.placement.translationMm = {-20 + 0.013 * seed, -20 + 0.007 * seed, 100};
    s.background = 200;
    s.addDisc({20, 20}, 1.75, 40);  // 17.5 px
    s.noiseSigma = 0.5;
    s.seed = static_cast<std::uint64_t>(seed);
    const cv::Mat image = s.render();
    const cv::Point2d truth = s.imageOf({20, 20});
    for (const double nominal : {20.0, 17.5}) {
      CircleMeasureParams p;
      p.centre = truth + cv::Point2d(0.3, -0.2);
      p.radius = nominal;
      p.width = 6;
      p.polarity = CirclePolarity::DarkToLight;
      const CircleMeasurement m = measureCircle(image, p);
      ASSERT_TRUE(m.status.ok()) << m.status.message;
      EXPECT_TRUE(m.greyRefined);
      EXPECT_LT(cv::norm(m.centre - truth), 0.01) << "seed " << seed << " nominal " << nominal;
      EXPECT_NEAR(m.radius, 17.5, 0.01) << "seed " << seed << " nominal " << nominal;
      // The equivalent blur: the pixel's box alone, sqrt(1/12).
      EXPECT_NEAR(m.blur, std::sqrt(1.0 / 12.0), 0.05);
      sum2 += std::pow(cv::norm(m.centre - truth), 2);
      ++n;
    }
  }
  EXPECT_LT(std::sqrt(sum2 / n), 0.005);
}

TEST(CircleMeasure, AbsurdAnnulusIsBadInput) {
  Scene s(spec(60, 60));
  auto p = params({30, 30}, 1e9, CirclePolarity::Any);
  const auto m = measureCircle(s.render(), p);
  EXPECT_EQ(m.status.cause, CircleFailure::BadInput) << m.status.message;
  p = params({1e12, 30}, 10, CirclePolarity::Any);
  EXPECT_EQ(measureCircle(s.render(), p).status.cause, CircleFailure::BadInput);
}

}  // namespace
}  // namespace facet
