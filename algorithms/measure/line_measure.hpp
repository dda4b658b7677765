#pragma once
// Line: the position, angle and straightness of a straight edge inside a rotated rectangle laid
// along it (Halcon's fit_line on measured edges, Cognex's line finder).
//
// The rectangle's axis runs along the expected line; the edge is searched across its width.
// Every `spacing` pixels along the axis a narrow caliper across the rectangle gives one subpixel
// edge point with the same symmetric estimator as the caliper tool (profile_edges.hpp), so a
// line at any angle gets unbiased points. The points are fitted robustly (line_fit.hpp).
// Across direction: the axis turned 90 degrees clockwise on screen, (sin a, cos a); "rising" is
// dark to light along it (for angle 0: dark above, light below).

#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "algorithms/measure/caliper.hpp"
#include "algorithms/measure/line_fit.hpp"
#include "algorithms/measure/measure_failure.hpp"
#include "algorithms/status/status.hpp"

namespace facet {

struct LineMeasureParams {
  EdgePolarity polarity = EdgePolarity::Any;
  double minAmplitude = 20.0;  // grey levels (8-bit scale)
  double spacing = 2.0;        // pixels between the cross calipers along the axis
  double stationWidth = 2.0;   // pixels each cross caliper averages along the axis
  // Profile samples every 0.5 px across (the caliper's 0.25 px costs twice the time here, for
  // the same noise: many points average the line).
  GreyProfileParams sampling{.step = 0.5, .crossStep = 0.5};
  // A step fit 4 px either side (the caliper's 8 px halves the noise of the levels, but here
  // many points average the line: 3% of its angle's precision for twice the fit's time).
  ProfileEdgeParams edges{.window = 4.0};
  LineFitParams fit;
};

struct LineMeasurement {
  cv::Point2d p1, p2;       // the segment covered by the inlier points, in axis order
  double angle = 0;         // degrees, counter-clockwise on screen, along the axis
  double rms = 0;           // pixels
  double straightness = 0;  // largest deviation of an inlier point from the line, pixels
  int points = 0;           // inlier edge points
  int stations = 0;         // cross calipers inside the image
  std::vector<cv::Point2d> edgePoints;  // every edge point found (inliers and outliers)
  std::vector<int> inliers;             // indices into edgePoints of the fit's inliers
  bool partial = false;                 // part of the rectangle lay outside the image
  // Inlier points beside grey values the sensor clipped (ProfileEdge::clipped): each lies up to a
  // pixel towards the unclipped side, so the line is offset by as much; lower the exposure.
  int clippedPoints = 0;
  Status<MeasureFailure> status;
};

LineMeasurement measureLine(const cv::Mat& image, const MeasuringRect& rect,
                            const LineMeasureParams& params = {});

}  // namespace facet
