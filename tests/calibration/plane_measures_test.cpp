// Caliper lengths and fitted lines carried into the measuring plane, against the renderer's exact
// projection of plane points (plane_measures.hpp).
#include "algorithms/calibration/plane_measures.hpp"

#include <cmath>

#include <gtest/gtest.h>

#include "tests/calibration/calibration_scenes.hpp"

namespace facet {
namespace {

struct TiltedPlane {
  scene::LensCamera camera = test::testCamera();
  scene::PlanePlacement placement = scene::lookAtPlane({40, 30}, 280, 35, 20, 10, camera);
  WorldMapping mapping{CameraModel{camera.matrix(), camera.distortion(), camera.size},
                       PlanePose{placement.rotation, placement.translationMm, 0.0}};
  [[nodiscard]] cv::Point2d pixelOf(cv::Point2d mm) const {
    return camera.project(placement.toCamera(mm));
  }
};

TEST(PlaneMeasures, WithoutAPlaneLengthsAndLinesStayInPixels) {
  const MeasuringPath rect(MeasuringRect{100, 80, 60, 10, 30});
  EXPECT_DOUBLE_EQ(spanInPlane(rect, nullptr, -12.5, 20.0), 32.5);
  // A line along the rectangle's axis, 3 px across it (towards (sin a, cos a)).
  const double a = 30 * CV_PI / 180;
  const cv::Point2d axis(std::cos(a), -std::sin(a)), across(std::sin(a), std::cos(a));
  LineMeasurement line;
  line.p1 = cv::Point2d(100, 80) - 25 * axis + 3 * across;
  line.p2 = cv::Point2d(100, 80) + 25 * axis + 3 * across;
  line.straightness = 0.2, line.rms = 0.1;
  const LineInPlane l = lineInPlane({100, 80, 60, 10, 30}, line, nullptr);
  EXPECT_NEAR(l.angleFromAxis, 0.0, 1e-9);
  EXPECT_NEAR(l.offset, 3.0, 1e-9);
  EXPECT_DOUBLE_EQ(l.straightness, 0.2);
  EXPECT_DOUBLE_EQ(l.rms, 0.1);
}

TEST(PlaneMeasures, ARectanglesSpanIsTheDistanceInThePlaneAlongItsAxis) {
  const TiltedPlane t;
  // A rectangle laid along the plane's x axis through (30, 30): its ends at x = 10 and 50.
  const cv::Point2d c = t.pixelOf({30, 30}), e = t.pixelOf({50, 30});
  const double angle = std::atan2(-(e - c).y, (e - c).x) * 180 / CV_PI;
  const MeasuringPath path(MeasuringRect{c.x, c.y, 2 * cv::norm(e - c), 10, angle});
  const double s = cv::norm(e - c);
  EXPECT_NEAR(spanInPlane(path, &t.mapping, 0.0, s), 20.0, 1e-6);
  // The other half is shorter in the image (the tilt), not in the plane.
  const double back = cv::norm(t.pixelOf({10, 30}) - c);
  EXPECT_GT(std::abs(back - s), 1.0);
  EXPECT_NEAR(spanInPlane(path, &t.mapping, -back, 0.0), 20.0, 0.05);
}

TEST(PlaneMeasures, AnArcsSpanIsItsPathLengthInThePlane) {
  const TiltedPlane t;
  const MeasuringArc arc{640, 500, 150, 10, 120, 8};
  const MeasuringPath path(arc);
  // The arc carried into the plane point by point, a thousand times finer than the tool's steps.
  double expected = 0.0;
  const double s0 = -40.0, s1 = 170.0;
  cv::Point2d from = t.mapping.toPlane(path.at(s0, 0));
  for (int i = 1; i <= 200000; ++i) {
    const cv::Point2d to = t.mapping.toPlane(path.at(s0 + (s1 - s0) * i / 200000.0, 0));
    expected += cv::norm(to - from);
    from = to;
  }
  EXPECT_NEAR(spanInPlane(path, &t.mapping, s0, s1), expected, 1e-4 * expected);
  EXPECT_NEAR(spanInPlane(path, &t.mapping, s1, s0), -expected, 1e-4 * expected);
}

TEST(PlaneMeasures, ALinesAngleAndOffsetAreThoseOfThePlane) {
  const TiltedPlane t;
  // In the plane: the rectangle's axis along x through (40, 30); the line 2 mm across it (towards
  // +y), turned 5 degrees counter-clockwise as seen with the plane's y down.
  // The rectangle is straight in the image: its axis follows the plane's x axis at its centre
  // (the lens bends the image of the plane's x axis away from a straight line).
  const cv::Point2d c = t.pixelOf({40, 30}), e = t.pixelOf({40.01, 30});
  const double angle = std::atan2(-(e - c).y, (e - c).x) * 180 / CV_PI;
  const MeasuringRect rect{c.x, c.y, 80, 30, angle};
  const double turn = 5 * CV_PI / 180;
  const cv::Point2d dir(std::cos(turn), -std::sin(turn));
  LineMeasurement line;
  line.p1 = t.pixelOf(cv::Point2d(40, 32) - 12 * dir);
  line.p2 = t.pixelOf(cv::Point2d(40, 32) + 12 * dir);
  line.straightness = 1.0;
  const LineInPlane l = lineInPlane(rect, line, &t.mapping);
  EXPECT_NEAR(l.angleFromAxis, 5.0, 1e-4);
  // The line meets x = 40, square to the axis through (40, 30), at y = 32: 2 mm.
  EXPECT_NEAR(l.offset, 2.0, 1e-5);
  EXPECT_NEAR(cv::norm(l.p1 - (cv::Point2d(40, 32) - 12 * dir)), 0.0, 1e-6);
  EXPECT_NEAR(l.straightness, t.mapping.mmPerPixelAt((line.p1 + line.p2) * 0.5), 1e-12);
}

}  // namespace
}  // namespace facet
