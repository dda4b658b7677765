// Circles measured in the measuring plane (plane_circle.hpp): rim points seen on a tilted plane
// through the test camera's distorting lens, against the circle they were taken from.
#include "algorithms/calibration/plane_circle.hpp"

#include <cmath>

#include <gtest/gtest.h>

#include "tests/calibration/calibration_scenes.hpp"

namespace facet {
namespace {

struct TiltedRim : test::TiltedPlane {
  // The image measurement of a rim of `radiusMm` about `centreMm`, its points exactly on it
  // (`bumpMm`: one point that far outside it).
  [[nodiscard]] CircleMeasurement measured(cv::Point2d centreMm, double radiusMm,
                                           double bumpMm = 0) const {
    CircleMeasurement m;
    for (int i = 0; i < 360; i += 3) {
      const double a = i * CV_PI / 180, r = radiusMm + (i == 90 ? bumpMm : 0.0);
      m.inlierPoints.push_back(pixelOf(centreMm + r * cv::Point2d(std::cos(a), std::sin(a))));
    }
    const auto image = fitCircle(m.inlierPoints);
    m.centre = image->centreMm;
    m.radius = image->diameterMm / 2;
    m.diameter = image->diameterMm;
    m.greyRefined = true;
    m.blur = 0;
    // circleInPlane moves each point out by the edge bias (0.6 / r px at blur 0) before mapping:
    // start that far inside so that the mapped rim is exact.
    for (auto& p : m.inlierPoints) {
      const cv::Point2d radial = p - m.centre;
      p -= radial * (0.6 / m.radius / cv::norm(radial));
    }
    return m;
  }
};

TEST(PlaneCircle, ARimSeenAtAnAngleIsRoundInThePlane) {
  const TiltedRim t;
  const CircleMeasurement m = t.measured({40, 30}, 10);
  const auto c = circleInPlane(m, t.mapping);
  ASSERT_TRUE(c.has_value());
  EXPECT_LT(cv::norm(c->centreMm - cv::Point2d(40, 30)), 1e-3);
  EXPECT_NEAR(c->diameterMm, 20, 1e-3);
  EXPECT_LT(c->roundnessMm, 1e-3);
  // In the image the rim is an ellipse: its points lie pixels off their own circle.
  const auto image = fitCircle(m.inlierPoints);
  EXPECT_GT(image->roundnessMm, 5.0);
}

TEST(PlaneCircle, ABumpOnTheRimIsItsRoundness) {
  const TiltedRim t;
  const auto c = circleInPlane(t.measured({40, 30}, 10, 0.05), t.mapping);
  ASSERT_TRUE(c.has_value());
  EXPECT_NEAR(c->roundnessMm, 0.05, 0.003);
}

}  // namespace
}  // namespace facet
