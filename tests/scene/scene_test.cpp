// The generator's own accuracy: the rendered coverage must reproduce the analytic area and
// centroid, otherwise every accuracy figure measured with it is meaningless.
#include <cmath>
#include <numbers>
#include <random>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include "tests/support/scene/parts.hpp"
#include "tests/support/scene/scene.hpp"

namespace facet::scene {
namespace {

cv::Point2d coverageCentroid(const cv::Mat& cov, double* mass) {
  const cv::Moments m = cv::moments(cov);
  *mass = m.m00;
  return {m.m10 / m.m00, m.m01 / m.m00};
}

TEST(SceneCoverage, PolygonCentroidAndAreaAtRandomSubpixelPoses) {
  std::mt19937_64 rng(42);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int trial = 0; trial < 20; ++trial) {
    const cv::Point2d c{60 + u(rng), 50 + u(rng)};
    const double a = u(rng) * 2 * std::numbers::pi;
    std::vector<cv::Point2d> v;
    const double radii[5] = {30, 18, 27, 12, 25};
    for (int i = 0; i < 5; ++i) {
      const double t = a + 2 * std::numbers::pi * i / 5;
      v.push_back({c.x + radii[i] * std::cos(t), c.y + radii[i] * std::sin(t)});
    }
    Primitive p;
    p.vertices = v;
    double mass = 0;
    const cv::Point2d got = coverageCentroid(renderCoverage(p, {128, 110}), &mass);
    const cv::Point2d want = polygonCentroid(v);
    EXPECT_NEAR(got.x, want.x, 0.01) << "trial " << trial;
    EXPECT_NEAR(got.y, want.y, 0.01) << "trial " << trial;
    EXPECT_NEAR(mass, polygonArea(v), 0.01 * polygonArea(v) / 100);
  }
}

TEST(SceneCoverage, DiscCentroidAndArea) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (double r : {3.0, 10.0, 40.5}) {
    Primitive p;
    p.kind = Primitive::Kind::Disc;
    p.centre = {50 + u(rng), 50.3 + u(rng)};
    p.radius = r;
    double mass = 0;
    const cv::Point2d got = coverageCentroid(renderCoverage(p, {101, 102}), &mass);
    EXPECT_NEAR(got.x, p.centre.x, 0.01);
    EXPECT_NEAR(got.y, p.centre.y, 0.01);
    EXPECT_NEAR(mass, std::numbers::pi * r * r, 1e-3 * r * r);
  }
}

TEST(SceneCoverage, AxisAlignedEdgeCoverageIsExact) {
  // A half-plane x < 10.3: pixel 10 covers [9.5, 10.5] so its coverage must be 0.8.
  Primitive p;
  p.vertices = {{-5, -5}, {10.3, -5}, {10.3, 30}, {-5, 30}};
  const cv::Mat cov = renderCoverage(p, {20, 20});
  EXPECT_NEAR(cov.at<double>(10, 10), 0.8, 1e-9);
  EXPECT_NEAR(cov.at<double>(10, 9), 1.0, 1e-9);
  EXPECT_NEAR(cov.at<double>(10, 11), 0.0, 1e-9);
}

TEST(Scene, RenderedImageCentroidMatchesGroundTruth) {
  SceneSpec spec;
  spec.size = {120, 100};
  spec.background = 0;
  Scene scene(spec);
  const cv::Point2d c{57.37, 48.81};
  scene.addDisc(c, 20, 200);
  cv::Mat image;
  scene.renderIdeal().convertTo(image, CV_64F);
  const cv::Moments m = cv::moments(image);
  EXPECT_NEAR(m.m10 / m.m00, c.x, 0.01);
  EXPECT_NEAR(m.m01 / m.m00, c.y, 0.01);
}

TEST(Scene, SixteenBitAndEightBitAgree) {
  SceneSpec spec;
  spec.size = {64, 48};
  Scene eight(spec);
  eight.addDisc({30.2, 20.7}, 9, 180);
  spec.depth = CV_16U;
  Scene sixteen(spec);
  sixteen.addDisc({30.2, 20.7}, 9, 180);
  const cv::Mat a = eight.render(), b = sixteen.render();
  ASSERT_EQ(a.type(), CV_8U);
  ASSERT_EQ(b.type(), CV_16U);
  cv::Mat b8;
  b.convertTo(b8, CV_64F, 1.0 / 256);
  cv::Mat a64;
  a.convertTo(a64, CV_64F);
  EXPECT_LE(cv::norm(a64, b8, cv::NORM_INF), 0.51);
}

TEST(Scene, NoiseBlurAndGradientChangeTheImageReproducibly) {
  SceneSpec spec;
  spec.size = {64, 64};
  spec.noiseSigma = 2;
  spec.blurSigma = 1;
  spec.illuminationGradient = {0.5, 0};
  Scene a(spec), b(spec);
  a.addDisc({32, 32}, 10, 150);
  b.addDisc({32, 32}, 10, 150);
  EXPECT_EQ(cv::norm(a.render(), b.render(), cv::NORM_INF), 0.0);
  const cv::Mat img = a.render();
  // The gradient makes the right border brighter than the left one.
  EXPECT_GT(cv::mean(img.col(63))[0], cv::mean(img.col(0))[0] + 20);
}

TEST(Scene, ClutterAvoidsKeepOutAndOccluderHidesShare) {
  SceneSpec spec;
  Scene scene(spec);
  const cv::Rect2d keep{200, 150, 150, 120};
  scene.addClutter(30, 10, 40, {keep});
  int clutter = 0;
  for (const auto& p : scene.primitives()) {
    ++clutter;
    if (p.kind == Primitive::Kind::Disc) {
      EXPECT_EQ((keep & cv::Rect2d(p.centre.x - p.radius, p.centre.y - p.radius, 2 * p.radius,
                                   2 * p.radius))
                    .area(),
                0.0);
    }
  }
  EXPECT_EQ(clutter, 30);
  const auto occ = scene.addOccluder(keep, 0.4, 10);
  const double hidden =
      (cv::boundingRect(std::vector<cv::Point2f>(occ.begin(), occ.end())) & cv::Rect(keep)).area();
  EXPECT_NEAR(hidden / keep.area(), 0.4, 0.03);
}

TEST(Parts, BracketPlacedAtPoseMovesItsHoles) {
  const PartDrawing bracket = bracketPart();
  SceneSpec spec;
  Scene scene(spec);
  const Pose2D pose{300.25, 200.75, radians(90), 1.0};
  placePart(scene, bracket, pose, 200, 40);
  // The first hole (-42, -28) under a +90 degree turn goes to t + (-28, 42) (R(90) =
  // [[0,1],[-1,0]]).
  const auto& hole = scene.primitives()[1];
  EXPECT_NEAR(hole.centre.x, 300.25 - 28, 1e-9);
  EXPECT_NEAR(hole.centre.y, 200.75 + 42, 1e-9);
}

}  // namespace
}  // namespace facet::scene
