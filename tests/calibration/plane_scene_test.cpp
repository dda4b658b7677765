// The plane-scene renderer against independent formulas: areas against the shoelace formula,
// projections against OpenCV's projectPoints, blur before integration against the pixel sum.
#include <cmath>
#include <random>
#include <utility>

#include <gtest/gtest.h>
#include <opencv2/calib3d.hpp>

#include "tests/support/scene/calibration_plates.hpp"
#include "tests/support/scene/plane_scene.hpp"

namespace facet::scene {
namespace {

double shoelace(const std::vector<cv::Point2d>& v) {
  double a = 0;
  for (std::size_t i = 0; i < v.size(); ++i) a += v[i].cross(v[(i + 1) % v.size()]);
  return std::abs(a) / 2;
}

LensCamera distortedCamera() {
  LensCamera c;
  c.k1 = -0.3, c.k2 = 0.1, c.p1 = 0.002, c.p2 = -0.001;
  return c;
}

// A 320x256 view of the plane around (10, 10) mm, tilted 30 degrees, through the distorted lens.
PlaneScene smallTiltedScene() {
  PlaneScene s;
  s.camera = distortedCamera();
  s.camera.size = {320, 256};
  s.camera.cx = 159.5, s.camera.cy = 127.5, s.camera.fx = s.camera.fy = 400;
  s.placement = lookAtPlane({10, 10}, 300, 30, 60, 15, s.camera);
  return s;
}

TEST(PlaneScene, CoverageSumsToTheOutlinesArea) {
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(0, 1);
  for (int trial = 0; trial < 20; ++trial) {
    std::vector<cv::Point2d> poly;
    const cv::Point2d c(30 + 20 * u(rng), 30 + 20 * u(rng));
    for (int i = 0; i < 7; ++i) {
      const double a = 2 * CV_PI * (i + 0.4 * u(rng)) / 7, r = 5 + 15 * u(rng);
      poly.push_back(c + r * cv::Point2d(std::cos(a), std::sin(a)));
    }
    const cv::Mat cov = polygonCoverage(poly, {80, 80});
    EXPECT_NEAR(cv::sum(cov)[0], shoelace(poly), 2e-4) << "trial " << trial;
    double lo, hi;
    cv::minMaxLoc(cov, &lo, &hi);
    EXPECT_GE(lo, -1e-12);
    EXPECT_LE(hi, 1 + 1e-12);
  }
}

TEST(PlaneScene, ProjectionAgreesWithOpenCv) {
  PlaneScene s;
  s.camera = distortedCamera();
  s.placement = lookAtPlane({50, 40}, 400, 35, 20, 10, s.camera);
  std::vector<cv::Point3d> plane;
  for (int i = 0; i < 50; ++i) plane.emplace_back(i * 2.1, 80 - i * 1.7, 0.0);
  cv::Mat rvec;
  cv::Rodrigues(cv::Mat(s.placement.rotation), rvec);
  std::vector<cv::Point2d> cvPoints;
  cv::projectPoints(plane, rvec, cv::Mat(s.placement.translationMm), cv::Mat(s.camera.matrix()),
                    s.camera.distortion(), cvPoints);
  for (std::size_t i = 0; i < plane.size(); ++i) {
    const cv::Point2d p = s.imageOf({plane[i].x, plane[i].y});
    EXPECT_NEAR(p.x, cvPoints[i].x, 1e-6);
    EXPECT_NEAR(p.y, cvPoints[i].y, 1e-6);
  }
}

TEST(PlaneScene, DarkAreaMatchesTheProjectedSquareWithAndWithoutLensBlur) {
  PlaneScene s = smallTiltedScene();
  s.background = 0;
  s.addPolygon({{0, 0}, {20, 0}, {20, 20}, {0, 20}}, 100);
  const double area = shoelace(projectOutline(s, s.shapes[0]));
  // Without blur the grey sum is 100 * area; a lens blur before integration keeps the sum.
  EXPECT_NEAR(cv::sum(s.renderIdeal())[0] / 100, area, 1e-3 * area);
  s.lensBlurSigma = 1.5;
  EXPECT_NEAR(cv::sum(s.renderIdeal())[0] / 100, area, 1e-3 * area);
}

TEST(PlaneScene, ChessboardCornersLieOnTheSquaresEdges) {
  PlaneScene s;
  s.camera = distortedCamera();
  s.placement = lookAtPlane({50, 35}, 450, 25, 0, 0, s.camera);
  addChessboardPlate(s, 11, 8, 10);
  const auto points = patternImagePoints(s, 11, 8, 10);
  ASSERT_EQ(points.size(), 88u);
  const cv::Mat image = s.renderIdeal();
  // At an inner corner four squares meet: the mean of the four neighbouring pixels is mid-grey.
  const cv::Point p = points[40];
  const double mid = (image.at<double>(p.y, p.x) + image.at<double>(p.y, p.x + 1) +
                      image.at<double>(p.y + 1, p.x) + image.at<double>(p.y + 1, p.x + 1)) /
                     4;
  EXPECT_NEAR(mid, 125, 40);
}

// A plate seen square on through a distortion-free lens at 10 px/mm: the squares are axis-aligned
// in the image, the plate origin at `cornerPx`, so a pixel's coverages are products of overlaps.
// With the corner's y on a multiple of 1/256 px the edge falls between two sub-scanlines and the
// analytic value is the renderer's exact answer.
PlaneScene squareOnScene(cv::Point2d cornerPx) {
  PlaneScene s;
  s.camera.size = {160, 120};
  s.camera.fx = s.camera.fy = 1000;
  s.camera.cx = cornerPx.x, s.camera.cy = cornerPx.y;
  s.placement.translationMm = {0, 0, 100};
  return s;
}

TEST(PlaneScene, ChessboardCornerPixelIsExact) {
  const double dark = 25, light = 225;
  // The corner at 0.3 of its pixel across and 0.25 down: the dark squares up-left and down-right
  // cover 0.3 * 0.25 and 0.7 * 0.75 of the pixel.
  const cv::Point2d corner(60.3 - 0.5, 50.25 - 0.5);
  const double a = 0.3, b = 0.25;
  const double darkShare = a * b + (1 - a) * (1 - b);
  const double exact = dark * darkShare + light * (1 - darkShare);

  PlaneScene s = squareOnScene(corner);
  addChessboardPlate(s, 3, 3, 1);
  const double value = s.renderIdeal().at<double>(50, 60);
  EXPECT_NEAR(value, exact, 1e-9);

  // The same squares painted one by one leave the second's share of the first's coverage light:
  // (light - dark) times the product of their coverages, 7.9 grey levels here.
  PlaneScene painter = squareOnScene(corner);
  painter.addPolygon({{-2, -2}, {4, -2}, {4, 4}, {-2, 4}}, light);
  for (const auto& square : s.shapes[1].morePolygons) painter.addPolygon(square, dark);
  painter.addPolygon(s.shapes[1].polygon, dark);
  const double painted = painter.renderIdeal().at<double>(50, 60);
  EXPECT_NEAR(painted - exact, (light - dark) * (a * b) * ((1 - a) * (1 - b)), 1e-9);
  EXPECT_GT(std::abs(painted - exact), 7.0);
}

TEST(PlaneScene, TouchingPolygonsOfOneShapePaintAsTheirUnion) {
  PlaneScene one = smallTiltedScene();
  one.background = 200;
  PlaneScene two = one, painter = one;
  one.addPolygon({{0, 0}, {20, 0}, {20, 20}, {0, 20}}, 40);
  const std::vector<cv::Point2d> left{{0, 0}, {8, 0}, {8, 20}, {0, 20}};
  const std::vector<cv::Point2d> right{{8, 0}, {20, 0}, {20, 20}, {8, 20}};
  two.addPolygons({left, right}, 40);
  painter.addPolygon(left, 40);
  painter.addPolygon(right, 40);
  // Painted one after the other, a pixel the shared edge halves stays a quarter light:
  // (200 - 40) / 4 = 40 grey levels off, spread by the lens blur to about 3.
  for (const auto& [blur, painterOff] : {std::pair{0.0, 30.0}, std::pair{1.2, 2.0}}) {
    one.lensBlurSigma = two.lensBlurSigma = painter.lensBlurSigma = blur;
    const cv::Mat reference = one.renderIdeal();
    // The shared edge is cut into chords at other points than the whole square's edge is, a few
    // 1e-6 px apart on the bent image of the edge: 2e-6 grey levels here.
    EXPECT_LT(cv::norm(two.renderIdeal() - reference, cv::NORM_INF), 1e-4) << "blur " << blur;
    EXPECT_GT(cv::norm(painter.renderIdeal() - reference, cv::NORM_INF), painterOff)
        << "blur " << blur;
  }
}

}  // namespace
}  // namespace facet::scene
