// The grey-value circle fit in the measuring plane (plane_circle_profile.hpp): holes rendered on a
// tilted plane through the test camera's distorting lens (exact pixel coverage, lens blur before
// pixel integration, noise), measured in the image as the circle step does, then in the plane.
#include "algorithms/calibration/plane_circle_profile.hpp"

#include <cmath>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "algorithms/calibration/plane_circle.hpp"
#include "algorithms/circle/circle_profile_fit.hpp"
#include "tests/calibration/calibration_scenes.hpp"
#include "tests/support/scene/plane_scene.hpp"

namespace facet {
namespace {

struct TiltedHoles {
  scene::PlaneScene scene;
  WorldMapping mapping;
  cv::Mat image;

  TiltedHoles(double tiltDeg, double lensBlur, std::uint64_t seed,
              const std::vector<std::pair<cv::Point2d, double>>& holes,
              const std::vector<std::vector<cv::Point2d>>& occluders = {},
              scene::LensCamera camera = test::testCamera(), double noise = 2, double plate = 210)
      : scene(make(tiltDeg, lensBlur, seed, holes, occluders, camera, noise, plate)),
        mapping(CameraModel{scene.camera.matrix(), scene.camera.distortion(), scene.camera.size},
                PlanePose{scene.placement.rotation, scene.placement.translationMm, 0.0}),
        image(scene.render()) {}

  static scene::PlaneScene make(double tiltDeg, double lensBlur, std::uint64_t seed,
                                const std::vector<std::pair<cv::Point2d, double>>& holes,
                                const std::vector<std::vector<cv::Point2d>>& occluders,
                                const scene::LensCamera& camera, double noise, double plate) {
    scene::PlaneScene s;
    s.camera = camera;
    s.placement = scene::lookAtPlane({40, 30}, 250, tiltDeg, 20, 10, s.camera);
    s.background = 30;
    s.addPolygon({{-20, -20}, {100, -20}, {100, 80}, {-20, 80}}, plate);
    for (const auto& [centre, radius] : holes) s.addDisc(centre, radius, 40);
    for (const auto& polygon : occluders) s.addPolygon(polygon, 210);
    s.lensBlurSigma = lensBlur;
    s.noiseSigma = noise;
    s.seed = seed;
    return s;
  }

  // The measuring parameters of the circle step for the hole about `centreMm`: annulus 35% of
  // the radius, the expected centre 0.7 px off.
  [[nodiscard]] CircleMeasureParams params(cv::Point2d centreMm, double radiusMm) const {
    const cv::Point2d c = scene.imageOf(centreMm);
    CircleMeasureParams p;
    p.centre = c + cv::Point2d(0.6, -0.4);
    p.radius = radiusMm / mapping.mmPerPixelAt(c);
    p.width = 0.35 * p.radius;
    p.polarity = CirclePolarity::DarkToLight;
    return p;
  }
  [[nodiscard]] CircleMeasurement measured(cv::Point2d centreMm, double radiusMm) const {
    return measureCircle(image, params(centreMm, radiusMm));
  }
};

const cv::Point2d kBig(20, 15), kSmall(60, 45);  // holes of radius 5 and 2.5 mm

// Holes of radius 5 and 2.5 mm (about 29 and 14 px) on a plane tilted 30 degrees (ellipses of
// 0.87 : 1 in the image), lens blur 0.7 px, noise 2: centre and diameter within 0.002 mm
// (0.012 px at the plane's scale; measured up to 0.0009), several times closer than the rim's
// edge points fitted in the plane (measured 0.0006 against 0.0046 mm RMS).
TEST(PlaneCircleProfile, AHoleSeenAt30DegreesIsMeasuredToTheGreyFitsPrecision) {
  double grey2 = 0, edges2 = 0;
  int n = 0;
  for (std::uint64_t seed = 1; seed <= 3; ++seed) {
    const TiltedHoles t(30, 0.7, seed, {{kBig, 5.0}, {kSmall, 2.5}});
    for (const auto& [c, r] : {std::pair{kBig, 5.0}, std::pair{kSmall, 2.5}}) {
      const CircleMeasurement m = t.measured(c, r);
      ASSERT_TRUE(m.status.ok() || refusedAsImageCircle(m)) << m.status.message;
      const auto g = circleInPlane(t.image, m, t.mapping);
      ASSERT_TRUE(g.has_value());
      EXPECT_TRUE(g->greyRefined);
      EXPECT_LT(cv::norm(g->centreMm - c), 0.002) << "seed " << seed << " r " << r;
      EXPECT_NEAR(g->diameterMm, 2 * r, 0.002) << "seed " << seed << " r " << r;
      if (const auto e = circleInPlane(m, t.mapping)) {
        grey2 += std::pow(cv::norm(g->centreMm - c), 2);
        edges2 += std::pow(cv::norm(e->centreMm - c), 2);
        ++n;
      }
    }
  }
  ASSERT_GE(n, 4);
  EXPECT_LT(3 * std::sqrt(grey2 / n), std::sqrt(edges2 / n));
}

// A plate lit 1.6 times beyond the sensor's clip (it reads 255 around the holes): fitted with the
// clip in the model, as the image's fit (clipped_rim_test.cpp), the centre within 0.005 mm and
// the diameter within 0.02 mm (measured -0.002 to -0.009 over 8 seeds; fitted as the pixels read,
// -0.14 to -0.15 mm). Four times beyond it the step's middle is not seen: the plane refuses the
// rim, with the cause, rather than give its edge points' circle.
TEST(PlaneCircleProfile, AClippedRimIsFittedAsClippedOrRefused) {
  for (std::uint64_t seed = 1; seed <= 2; ++seed) {
    const TiltedHoles t(30, 0.7, seed, {{kBig, 5.0}}, {}, test::testCamera(), 2, 400);
    const CircleMeasurement m = t.measured(kBig, 5.0);
    EXPECT_GT(m.clippedShare, 0.2);
    const PlaneCircleVerdict v = measureCircleInPlane(t.image, m, t.params(kBig, 5.0), t.mapping);
    ASSERT_TRUE(v.circle.has_value()) << m.status.message << " " << v.refusal;
    EXPECT_TRUE(v.circle->greyRefined);
    EXPECT_LT(cv::norm(v.circle->centreMm - kBig), 0.005) << "seed " << seed;
    EXPECT_NEAR(v.circle->diameterMm, 10.0, 0.02) << "seed " << seed;
  }
  const TiltedHoles over(30, 0.7, 1, {{kBig, 5.0}}, {}, test::testCamera(), 2, 1000);
  const CircleMeasurement m = over.measured(kBig, 5.0);
  const PlaneCircleVerdict v =
      measureCircleInPlane(over.image, m, over.params(kBig, 5.0), over.mapping);
  EXPECT_FALSE(v.circle.has_value());
  EXPECT_NE(v.refusal.find("clipped"), std::string::npos) << v.refusal;
}

// Without lens blur (pixel integration alone, the sharpest image a sensor gives), where a
// resampled square-on view came out 0.4 px off and the Gaussian profile alone 0.0011-0.0015 mm
// RMS (bench_plane_measures): with the pixel's area in the model within 0.001 mm (0.006 px;
// measured 0.0002-0.0003 mm RMS in the benchmark).
TEST(PlaneCircleProfile, ASharpImageToo) {
  for (const double tilt : {20.0, 30.0})
    for (std::uint64_t seed = 1; seed <= 2; ++seed) {
      const TiltedHoles t(tilt, 0.0, seed, {{kBig, 5.0}, {kSmall, 2.5}});
      for (const auto& [c, r] : {std::pair{kBig, 5.0}, std::pair{kSmall, 2.5}}) {
        const CircleMeasurement m = t.measured(c, r);
        const auto g = circleInPlane(t.image, m, t.mapping);
        ASSERT_TRUE(g.has_value()) << m.status.message;
        EXPECT_TRUE(g->greyRefined);
        EXPECT_LT(cv::norm(g->centreMm - c), 0.001) << "tilt " << tilt << " r " << r;
        EXPECT_NEAR(g->diameterMm, 2 * r, 0.001) << "tilt " << tilt << " r " << r;
      }
    }
}

// A plane square to the optical axis through a lens without distortion is the image scaled: on
// the same pixels (neither fit told the noise, so that neither thins its band or screens
// gradients) the fit in the plane is the image's grey-value fit (circle_profile_fit.hpp) carried
// into it, up to their robust weights (set at every step here, in the first two there).
TEST(PlaneCircleProfile, SquareOnWithoutDistortionItIsTheImagesFit) {
  scene::LensCamera straight = test::testCamera();
  straight.k1 = straight.k2 = straight.p1 = straight.p2 = straight.k3 = 0;
  TiltedHoles t(0, 0.7, 1, {{kBig, 5.0}}, {}, straight);
  t.scene.placement.rotation = cv::Matx33d::eye();
  t.scene.placement.translationMm = {-40, -30, 250};
  t.mapping =
      WorldMapping(CameraModel{straight.matrix(), straight.distortion(), straight.size},
                   PlanePose{t.scene.placement.rotation, t.scene.placement.translationMm, 0});
  t.image = t.scene.render();
  const CircleMeasurement m = t.measured(kBig, 5.0);
  ASSERT_TRUE(m.status.ok()) << m.status.message;
  const auto start = circleInPlane(m, t.mapping);
  ASSERT_TRUE(start.has_value());
  const double scale = t.mapping.mmPerPixelAt(m.centre);
  const auto plane = fitPlaneCircleProfile(t.image, t.mapping, start->centreMm,
                                           start->diameterMm / 2, m.inlierPoints);
  const auto image = fitCircleProfile(t.image, t.mapping.toImage(start->centreMm),
                                      start->diameterMm / 2 / scale, m.inlierPoints);
  ASSERT_TRUE(plane.has_value());
  ASSERT_TRUE(image.has_value());
  EXPECT_LT(cv::norm(t.mapping.toImage(plane->centreMm) - image->centre), 2e-3);
  EXPECT_NEAR(plane->radiusMm / scale, image->radius, 2e-3);
  EXPECT_NEAR(plane->blur, image->blur, 0.01);
}

// At 55 degrees the rim is an ellipse of 0.57 : 1. The image fit's 0.5 px band about a circle
// keeps too little of the smaller hole's, and the edge points' ellipse there covers too little
// of it (166 degrees): refused. In the plane the same tests pass and the hole measures within
// 0.002 mm. The larger hole's rim the image measures as its ellipse, from the grey values.
TEST(PlaneCircleProfile, AHoleTheImageRefusesAsACircleIsMeasuredInThePlane) {
  const cv::Point2d a(25, 49), b(45, 27);
  const TiltedHoles t(55, 0.7, 1, {{a, 4.0}, {b, 5.0}});
  const CircleMeasurement inImage = t.measured(b, 5.0);
  ASSERT_TRUE(inImage.status.ok()) << inImage.status.message;
  EXPECT_TRUE(inImage.elliptic);
  EXPECT_NEAR(inImage.minorDiameter / inImage.majorDiameter, std::cos(55 * CV_PI / 180), 0.02);
  for (const auto& [c, r] : {std::pair{a, 4.0}}) {
    const CircleMeasurement m = t.measured(c, r);
    ASSERT_FALSE(m.status.ok());
    ASSERT_TRUE(refusedAsImageCircle(m)) << m.status.message;
    EXPECT_FALSE(circleInPlane(m, t.mapping).has_value());  // the edge points alone: nothing
    const auto g = circleInPlane(t.image, m, t.mapping);
    ASSERT_TRUE(g.has_value());
    EXPECT_EQ(refusalInPlane(*g, t.params(c, r), t.mapping), "");
    EXPECT_GE(g->coverageDeg, 300);
    EXPECT_TRUE(g->greyRefined);
    EXPECT_LT(cv::norm(g->centreMm - c), 0.002);
    EXPECT_NEAR(g->diameterMm, 2 * r, 0.002);
    // What the circle step and the command ask: the same circle, judged in the plane.
    const PlaneCircleVerdict v = measureCircleInPlane(t.image, m, t.params(c, r), t.mapping);
    EXPECT_TRUE(v.judgedInPlane);
    EXPECT_EQ(v.refusal, "");
    ASSERT_TRUE(v.circle.has_value());
    EXPECT_EQ(v.circle->centreMm, g->centreMm);
    EXPECT_EQ(v.circle->diameterMm, g->diameterMm);
  }
}

// A rim that is no circle in the plane either stays refused: a hole with three quarters hidden
// under the plate (only its lower left quarter open) covers about 90 degrees there too.
TEST(PlaneCircleProfile, AHiddenRimIsRefusedInThePlaneToo) {
  const cv::Point2d c(45, 27);
  const TiltedHoles t(
      40, 0.7, 1, {{c, 5.0}},
      {{{45, 15}, {60, 15}, {60, 40}, {45, 40}}, {{30, 15}, {45, 15}, {45, 27}, {30, 27}}});
  const CircleMeasurement m = t.measured(c, 5.0);
  ASSERT_FALSE(m.status.ok());
  ASSERT_TRUE(refusedAsImageCircle(m)) << m.status.message;
  const auto g = circleInPlane(t.image, m, t.mapping);
  ASSERT_TRUE(g.has_value());
  const std::string why = refusalInPlane(*g, t.params(c, 5.0), t.mapping);
  EXPECT_NE(why.find("in the plane too"), std::string::npos) << why;
  EXPECT_LT(g->coverageDeg, 120);
  const PlaneCircleVerdict v = measureCircleInPlane(t.image, m, t.params(c, 5.0), t.mapping);
  EXPECT_TRUE(v.judgedInPlane);
  EXPECT_FALSE(v.circle.has_value());
  EXPECT_EQ(v.refusal, why);
}

// A measurement the image accepted is measured in the plane without a judgement there; one that
// failed for another cause than its circle's shape (here: its annulus lies off the image) gives
// nothing to measure and no refusal of the plane's.
TEST(PlaneCircleProfile, OnlyARimRefusedAsACircleIsJudgedInThePlane) {
  const TiltedHoles t(30, 0.7, 1, {{kBig, 5.0}});
  const CircleMeasureParams p = t.params(kBig, 5.0);
  const CircleMeasurement m = measureCircle(t.image, p);
  ASSERT_TRUE(m.status.ok()) << m.status.message;
  const PlaneCircleVerdict v = measureCircleInPlane(t.image, m, p, t.mapping);
  EXPECT_FALSE(v.judgedInPlane);
  ASSERT_TRUE(v.circle.has_value());
  EXPECT_LT(cv::norm(v.circle->centreMm - kBig), 0.002);

  CircleMeasureParams off = p;
  off.centre = {-500, -500};
  const CircleMeasurement outside = measureCircle(t.image, off);
  ASSERT_EQ(outside.status.cause, CircleFailure::AnnulusOutsideImage);
  const PlaneCircleVerdict none = measureCircleInPlane(t.image, outside, off, t.mapping);
  EXPECT_FALSE(none.circle.has_value());
  EXPECT_FALSE(none.judgedInPlane);
  EXPECT_EQ(none.refusal, "");
}

// The circle step on a calibrated station measures the image's edge points without the image's
// grey fit (nothing uses it there); `facet circle --calibration` keeps it for its pixel values.
// Both give the same circle in the plane.
TEST(PlaneCircleProfile, TheImagesOwnGreyFitDoesNotChangeTheCircleInThePlane) {
  const TiltedHoles t(10, 0.7, 2, {{kBig, 5.0}, {kSmall, 2.5}});
  for (const auto& [c, r] : {std::pair{kBig, 5.0}, std::pair{kSmall, 2.5}}) {
    CircleMeasureParams p = t.params(c, r);
    const CircleMeasurement withGrey = measureCircle(t.image, p);
    p.refineWithGreyValues = false;
    const CircleMeasurement edgesOnly = measureCircle(t.image, p);
    ASSERT_TRUE(withGrey.status.ok()) << withGrey.status.message;
    ASSERT_TRUE(withGrey.greyRefined);
    ASSERT_FALSE(edgesOnly.greyRefined);
    const auto a = circleInPlane(t.image, withGrey, t.mapping);
    const auto b = circleInPlane(t.image, edgesOnly, t.mapping);
    ASSERT_TRUE(a.has_value() && b.has_value());
    EXPECT_TRUE(b->greyRefined);
    EXPECT_EQ(a->centreMm, b->centreMm);
    EXPECT_EQ(a->diameterMm, b->diameterMm);
    EXPECT_LT(cv::norm(b->centreMm - c), 0.002);
  }
}

// The plane's tests pass only on figures that pass: a coverage, RMS, diameter or centre that is
// not a number refuses the circle.
TEST(PlaneCircleProfile, ACircleWithAFigureThatIsNotANumberIsRefusedInThePlane) {
  const TiltedHoles t(30, 0.7, 1, {{kBig, 5.0}});
  const CircleMeasureParams p = t.params(kBig, 5.0);
  const auto good = circleInPlane(t.image, measureCircle(t.image, p), t.mapping);
  ASSERT_TRUE(good.has_value());
  ASSERT_EQ(refusalInPlane(*good, p, t.mapping), "");
  const double nan = std::numeric_limits<double>::quiet_NaN();
  for (int field = 0; field < 4; ++field) {
    PlaneCircle c = *good;
    if (field == 0) c.coverageDeg = nan;
    if (field == 1) c.rmsMm = nan;
    if (field == 2) c.diameterMm = nan;
    if (field == 3) c.centreMm.x = nan;
    EXPECT_NE(refusalInPlane(c, p, t.mapping), "") << "field " << field;
  }
}

TEST(PlaneCircleProfile, RefusesWhatItCannotFit) {
  const TiltedHoles t(30, 0.7, 1, {{kBig, 5.0}});
  const CircleMeasurement m = t.measured(kBig, 5.0);
  ASSERT_TRUE(m.status.ok() || refusedAsImageCircle(m)) << m.status.message;
  const auto start = circleInPlane(m, t.mapping);
  ASSERT_TRUE(start.has_value());
  const double r = start->diameterMm / 2;
  // Fewer than 3 rim points, a colour image, an image without contrast.
  EXPECT_FALSE(fitPlaneCircleProfile(t.image, t.mapping, start->centreMm, r,
                                     {m.inlierPoints[0], m.inlierPoints[1]})
                   .has_value());
  cv::Mat colour;
  cv::cvtColor(t.image, colour, cv::COLOR_GRAY2BGR);
  EXPECT_FALSE(
      fitPlaneCircleProfile(colour, t.mapping, start->centreMm, r, m.inlierPoints).has_value());
  const cv::Mat flat(t.image.size(), CV_8U, cv::Scalar(128));
  EXPECT_FALSE(
      fitPlaneCircleProfile(flat, t.mapping, start->centreMm, r, m.inlierPoints).has_value());
  // A start off by more than the allowed shift: nothing rather than a far-off circle.
  const double px = t.mapping.mmPerPixelAt(m.centre);
  const auto far = fitPlaneCircleProfile(t.image, t.mapping, start->centreMm, r + 3 * px,
                                         m.inlierPoints, {}, 2.0, 1.0);
  EXPECT_FALSE(far.has_value());
}

}  // namespace
}  // namespace facet
