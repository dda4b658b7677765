// Caliper lengths and fitted lines carried into the measuring plane, against the renderer's exact
// projection of plane points (plane_measures.hpp).
#include "algorithms/calibration/plane_measures.hpp"

#include <cmath>
#include <utility>

#include <gtest/gtest.h>

#include "tests/calibration/calibration_scenes.hpp"

namespace facet {
namespace {

using test::TiltedPlane;

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
  const LineInPlane l = *lineInPlane({100, 80, 60, 10, 30}, line, nullptr);
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

TEST(PlaneMeasures, APairsMiddleIsHalfwayInThePlane) {
  const TiltedPlane t;
  // A 20 mm slot centred 2 mm from the rectangle's centre (30, 30), along the plane direction in
  // which the view's tilt changes the scale most.
  const cv::Point2d centre(30, 30);
  cv::Point2d dir;
  double steepest = 0;
  for (int deg = 0; deg < 180; ++deg) {
    const cv::Point2d d(std::cos(deg * CV_PI / 180), std::sin(deg * CV_PI / 180));
    const double ahead = cv::norm(t.pixelOf(centre + 10 * d) - t.pixelOf(centre));
    const double behind = cv::norm(t.pixelOf(centre) - t.pixelOf(centre - 10 * d));
    if (std::abs(ahead - behind) > steepest) steepest = std::abs(ahead - behind), dir = d;
  }
  const cv::Point2d c = t.pixelOf(centre), e = t.pixelOf(centre + 0.01 * dir);
  const cv::Point2d axis = (e - c) / cv::norm(e - c);
  const double angle = std::atan2(-axis.y, axis.x) * 180 / CV_PI;
  const MeasuringPath path(MeasuringRect{c.x, c.y, 300, 10, angle});
  const double s0 = (t.pixelOf(centre - 8 * dir) - c).dot(axis);
  const double s1 = (t.pixelOf(centre + 12 * dir) - c).dot(axis);
  const double mid = midpointInPlane(path, &t.mapping, s0, s1);
  EXPECT_NEAR(spanInPlane(path, &t.mapping, 0.0, mid), 2.0, 1e-3);
  EXPECT_NEAR(spanInPlane(path, &t.mapping, s0, mid), spanInPlane(path, &t.mapping, mid, s1), 1e-9);
  // The image's halfway point is 0.2 mm from the slot's middle.
  EXPECT_GT(std::abs(spanInPlane(path, &t.mapping, 0.0, (s0 + s1) / 2) - 2.0), 0.15);
  // Without a plane: halfway in pixels.
  EXPECT_DOUBLE_EQ(midpointInPlane(path, nullptr, s0, s1), (s0 + s1) / 2);
  // Along an arc: halfway along its path in the plane, whichever way round.
  const MeasuringPath arc(MeasuringArc{640, 500, 150, 10, 120, 8});
  for (const auto& [from, to] : {std::pair{-40.0, 170.0}, std::pair{170.0, -40.0}}) {
    const double m = midpointInPlane(arc, &t.mapping, from, to);
    EXPECT_NEAR(spanInPlane(arc, &t.mapping, from, m), spanInPlane(arc, &t.mapping, m, to), 1e-6);
    EXPECT_GT(std::abs(m - (from + to) / 2), 1.0);
  }
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
  // Made by hand, without its points: carried by its ends.
  const LineInPlane l = *lineInPlane(rect, line, &t.mapping);
  EXPECT_NEAR(l.angleFromAxis, 5.0, 1e-4);
  // The line meets x = 40, square to the axis through (40, 30), at y = 32: 2 mm.
  EXPECT_NEAR(l.offset, 2.0, 1e-5);
  EXPECT_NEAR(cv::norm(l.p1 - (cv::Point2d(40, 32) - 12 * dir)), 0.0, 1e-6);
  EXPECT_NEAR(l.straightness, t.mapping.mmPerPixelAt((line.p1 + line.p2) * 0.5), 1e-12);
}

// A straight edge far from the image centre is bowed in the image by the lens; fitted in the
// plane from its edge points, it is straight and in its place.
TEST(PlaneMeasures, AnEdgeBowedByTheLensIsStraightInThePlane) {
  const TiltedPlane t;
  // In the plane: the line y = 95 + 0.1 (x - 40) for x from 10 to 70, near the image's border.
  const auto onLine = [](double x) { return cv::Point2d(x, 95 + 0.1 * (x - 40)); };
  const cv::Point2d c = t.pixelOf(onLine(40)), e = t.pixelOf(onLine(40.01));
  const double angle = std::atan2(-(e - c).y, (e - c).x) * 180 / CV_PI;
  LineMeasurement line;
  for (double x = 10; x <= 70; x += 0.25) line.edgePoints.push_back(t.pixelOf(onLine(x)));
  const auto fit = fitLineRobust(line.edgePoints);
  ASSERT_TRUE(fit.has_value());
  line.inliers = fit->inliers;
  line.p1 = t.pixelOf(onLine(10)), line.p2 = t.pixelOf(onLine(70));
  line.straightness = fit->straightness, line.rms = fit->rms;
  const MeasuringRect rect{c.x, c.y, cv::norm(line.p2 - line.p1) + 20, 30, angle};
  const auto l = lineInPlane(rect, line, &t.mapping);
  ASSERT_TRUE(l.has_value());
  // The image's own fit sees a bow of 0.3 px; its ends carried into the plane (the line through
  // them is the chord of the bow) put the line 0.09 mm off, and call it 0.08 mm crooked.
  LineMeasurement ends;
  const LineSegment seg = inlierSegment(*fit, line.edgePoints, line.p2 - line.p1);
  ends.p1 = seg.p1, ends.p2 = seg.p2;
  ends.straightness = fit->straightness;
  const auto chord = lineInPlane(rect, ends, &t.mapping);
  ASSERT_TRUE(chord.has_value());
  EXPECT_GT(std::abs(chord->offset), 0.05);
  EXPECT_GT(chord->straightness, 0.05);
  EXPECT_LT(l->straightness, 1e-4);
  EXPECT_NEAR(l->offset, 0.0, 1e-4);
  EXPECT_NEAR(l->angleFromAxis, 0.0, 3e-3);
  EXPECT_LT(cv::norm(l->p1 - onLine(10)), 1e-3);
  EXPECT_LT(cv::norm(l->p2 - onLine(70)), 1e-3);
  EXPECT_GT(fit->straightness, 0.2);
}

}  // namespace
}  // namespace facet
