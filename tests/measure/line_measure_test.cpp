// Line: angle, position, extent and straightness of a straight edge; robustness to a burr; the
// failures with their causes.
#include <gtest/gtest.h>

#include "algorithms/measure/line_measure.hpp"
#include "tests/measure/edge_images.hpp"

namespace facet {
namespace {

using test::axisOf;

// Signed distance of p from the line through `through` with direction `dir`.
double offset(cv::Point2d p, cv::Point2d through, cv::Point2d dir) {
  const cv::Point2d d = p - through;
  return d.x * dir.y - d.y * dir.x;
}

TEST(LineMeasure, GivesAngleAndPositionOfAStraightEdge) {
  for (double angle : {0.0, 23.4, 90.0, 151.7, -66.0}) {
    const cv::Point2d through(100.3, 99.6), dir = axisOf(angle);
    const cv::Point2d across(-dir.y, dir.x);  // the light side, (sin a, cos a)
    const cv::Mat image = test::gridEdgeImage({200, 200}, through, across, 60, 180, 0.9, 1.0, 11);
    // Laid 0.5 degrees off the line and 2 px beside it, as a user would place it.
    const cv::Point2d c = through + 2.0 * across;
    const LineMeasurement m = measureLine(image, {c.x, c.y, 150, 16, angle + 0.5});
    ASSERT_TRUE(m.status.ok()) << angle << ": " << m.status.message;
    EXPECT_NEAR(std::remainder(m.angle - angle, 360.0), 0.0, 0.01) << angle;
    // Noise 1 over 75 points of 150 px: the ends' offsets scatter about 0.01 px.
    EXPECT_NEAR(offset(m.p1, through, dir), 0.0, 0.03) << angle;
    EXPECT_NEAR(offset(m.p2, through, dir), 0.0, 0.03) << angle;
    EXPECT_NEAR(cv::norm(m.p2 - m.p1), 149, 2.0) << angle;
    EXPECT_GT((m.p2 - m.p1).dot(dir), 0) << angle;  // in axis order
    EXPECT_GT(m.points, 70) << angle;               // one per 2 px
    EXPECT_LT(m.rms, 0.05) << angle;
    EXPECT_LT(m.straightness, 0.2) << angle;
    EXPECT_FALSE(m.partial);
  }
}

TEST(LineMeasure, IgnoresABurrAndThePolarityItWasNotAskedFor) {
  scene::SceneSpec spec;
  spec.size = {200, 100};
  spec.background = 50;
  spec.blurSigma = 0.9;
  spec.noiseSigma = 1.0;
  spec.subrows = 64;
  scene::Scene s(spec);
  s.addPolygon({{-10, 50.3}, {210, 50.3}, {210, 120}, {-10, 120}}, 170);  // light below y = 50.3
  s.addPolygon({{90, 50.3}, {102, 50.3}, {96, 46.0}}, 170);               // a burr 4.3 px high
  const cv::Mat image = s.render();
  LineMeasureParams p;
  const LineMeasurement m = measureLine(image, {99.5, 50, 180, 16, 0.0}, p);
  ASSERT_TRUE(m.status.ok()) << m.status.message;
  EXPECT_NEAR(m.angle, 0.0, 0.01);
  EXPECT_NEAR(m.p1.y, 50.3, 0.02);
  EXPECT_NEAR(m.p2.y, 50.3, 0.02);
  EXPECT_LT(m.points, 89);  // 90 stations: the burr's points are outliers
  // At angle 0 the across direction points down: dark above, light below is rising.
  p.polarity = EdgePolarity::Falling;
  EXPECT_EQ(measureLine(image, {99.5, 50, 180, 16, 0.0}, p).status.cause,
            MeasureFailure::TooFewPoints);
  p.polarity = EdgePolarity::Rising;
  EXPECT_TRUE(measureLine(image, {99.5, 50, 180, 16, 0.0}, p).status.ok());
}

// The strongest edge of a comb whose teeth lie closer than about five blur widths (two light bars
// of 4 px, 4 px apart, the second dimmer, blur 1.5, all four edges within each station's
// profile): the single-edge fits there are biased (0.18 px here) or degenerate into huge
// opposite steps, the strongest of which was taken for the line's point; the stations' crowded
// edges are fitted together (edge_cluster_fit.hpp).
TEST(LineMeasure, AnEdgeOfACombFinerThanItsBlurKeepsItsPlace) {
  for (const auto model : {scene::BlurModel::PixelGrid, scene::BlurModel::Lens}) {
    scene::SceneSpec spec;
    spec.size = {200, 100};
    spec.background = 60;
    spec.blurSigma = 1.5;
    spec.blurModel = model;
    spec.noiseSigma = 0.0;
    spec.subrows = 64;
    scene::Scene s(spec);
    // Bars of 4 px, 4 px apart, turned 3 degrees off the pixel rows (along a row the profile's
    // linear interpolation between pixels moves any edge by up to 0.02 px, another matter). The
    // first bar's upper edge passes through (100, 44.3).
    const double slope = std::tan(3.0 * CV_PI / 180.0), top = 44.3;
    auto band = [&](double from, double to, double grey) {
      s.addPolygon({{-10, from - 110 * slope},
                    {210, from + 110 * slope},
                    {210, to + 110 * slope},
                    {-10, to - 110 * slope}},
                   grey);
    };
    band(top, top + 4.0, 170);
    band(top + 8.0, top + 12.0, 130);
    const cv::Mat image = s.render();
    LineMeasureParams p;
    p.polarity = EdgePolarity::Rising;  // dark above, light below
    // Across it from 38 to 62 px: the whole comb (an edge just beyond the profile's end, its blur
    // reaching in, is not modelled: with the rectangle 16 px wide the line lay 0.06 px off).
    const LineMeasurement m = measureLine(image, {99.5, 50.0, 160, 24, -3.0}, p);
    ASSERT_TRUE(m.status.ok()) << m.status.message;
    EXPECT_NEAR(m.angle, -3.0, 0.01);
    // Distance of the ends from the edge's line (the second bar's edge lies 8 px below).
    const double c = std::cos(3.0 * CV_PI / 180.0);
    EXPECT_NEAR((m.p1.y - top - slope * (m.p1.x - 100)) * c, 0.0, 0.03);
    EXPECT_NEAR((m.p2.y - top - slope * (m.p2.x - 100)) * c, 0.0, 0.03);
    EXPECT_GT(m.points, 70);  // 80 stations
  }
}

TEST(LineMeasure, FailsWithItsCause) {
  const cv::Mat edge = test::gridEdgeImage({100, 100}, {50, 50.3}, {0, 1}, 50, 170, 0.9, 1.0);
  const cv::Mat flat(100, 100, CV_8U, cv::Scalar(90));
  EXPECT_EQ(measureLine(edge, {500, 500, 80, 16, 0}).status.cause, MeasureFailure::OutsideImage);
  EXPECT_EQ(measureLine(edge, {50, 50, 80, 0, 0}).status.cause, MeasureFailure::ZeroSize);
  EXPECT_EQ(measureLine(flat, {50, 50, 80, 16, 0}).status.cause, MeasureFailure::NoContrast);
  // Partly outside: measured on the inside part, and flagged.
  const LineMeasurement part = measureLine(edge, {90, 50, 80, 16, 0});
  ASSERT_TRUE(part.status.ok()) << part.status.message;
  EXPECT_TRUE(part.partial);
  EXPECT_NEAR(part.p1.y, 50.3, 0.03);
}

}  // namespace
}  // namespace facet
