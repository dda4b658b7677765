// The plane-scene renderer against independent formulas: areas against the shoelace formula,
// projections against OpenCV's projectPoints, blur before integration against the pixel sum.
#include <cmath>
#include <random>

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
  PlaneScene s;
  s.camera = distortedCamera();
  s.camera.size = {320, 256};
  s.camera.cx = 159.5, s.camera.cy = 127.5, s.camera.fx = s.camera.fy = 400;
  s.placement = lookAtPlane({10, 10}, 300, 30, 60, 15, s.camera);
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

}  // namespace
}  // namespace facet::scene
