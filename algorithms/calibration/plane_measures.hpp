#pragma once
// The caliper's and the line's results as the measuring plane sees them, in mm: lengths along a
// caliper's axis and a fitted line's angle, offset and deviations. The image of the plane is
// stretched unevenly by the lens and the view's tilt, so a length in pixels times one scale is
// not the part's length; the points are carried into the plane and measured there.
//
// `plane` null: the image is the plane (results in pixels), so a recipe step and a command give
// the same numbers with and without a lens model.

#include <optional>

#include <opencv2/core.hpp>

#include "algorithms/calibration/world_mapping.hpp"
#include "algorithms/measure/line_measure.hpp"
#include "algorithms/measure/measuring_path.hpp"

namespace facet {

// Signed length from axis position s0 to s1: a rectangle's along its axis as the plane sees it
// (an edge's distance from the centre, a pair's width); an arc's by summing its path carried
// into the plane in steps of about a pixel (its image is no circle under perspective).
double spanInPlane(const MeasuringPath& path, const WorldMapping* plane, double s0, double s1);

// The axis position halfway from s0 to s1 as the plane sees it: a pair's middle. Under
// perspective the image's halfway point is not (a 20 mm slot on a plane tilted 35 degrees, 280 mm
// from the camera: 0.2 mm off along the axis). Without a plane (s0 + s1) / 2; NaN where the path
// leaves the plane.
double midpointInPlane(const MeasuringPath& path, const WorldMapping* plane, double s0, double s1);

struct LineInPlane {
  cv::Point2d p1, p2;  // the segment's ends in the plane
  // The line's angle from the rectangle's axis, degrees counter-clockwise on screen (the plane's
  // y axis points down the image as pixels do).
  double angleFromAxis = 0;
  // Where the line crosses the line through the rectangle's centre square to its axis (both as
  // the plane sees them), signed towards the rectangle's across direction (the axis turned
  // clockwise on screen).
  double offset = 0;
  double straightness = 0, rms = 0;  // of the edge points about the line
};

// With a plane the line is fitted there: the measurement's inlier edge points are carried into
// the plane and fitted again with the same robust fit (line_fit.hpp). A lens bends the image of a
// straight edge: the image's fit called a 60 mm edge near the border of the tests' view (k1
// -0.22) 0.08 mm crooked and put it 0.09 mm off (a bow of 0.3 px); in the plane it is straight.
// A measurement without its points (made by hand) is carried by its ends, its deviations by the
// plane's scale there. nullopt when a point does not map into the plane.
std::optional<LineInPlane> lineInPlane(const MeasuringRect& rect, const LineMeasurement& line,
                                       const WorldMapping* plane);

}  // namespace facet
