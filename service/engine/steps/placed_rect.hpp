#pragma once
// A measuring rectangle as a recipe writes it (caliper, line, blob): centre, length, width and
// angle in the frame of the relative_to step (pixels of its reference, degrees counter-clockwise
// on screen), placed in the live image by that step's pose, so that the tool follows the part.
// The caliper's arc likewise: centre, radius, start angle, extent and radial width.

#include <optional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "algorithms/measure/measuring_path.hpp"
#include "config/step_fields.hpp"
#include "service/engine/overlay.hpp"

namespace facet::service {

// The rectangle's keys; P has centre, length, width and angle members.
template <class P>
void addMeasuringRect(config::StepFields<P>& f, const std::string& lengthDoc,
                      const std::string& widthDoc) {
  f.point("centre", &P::centre,
          "Centre [x, y] of the rectangle, pixels of the relative_to step's reference image.",
          true);
  f.number("length", &P::length, lengthDoc,
           {.minimum = 0.0, .exclusiveMinimum = true, .required = true});
  f.number("width", &P::width, widthDoc,
           {.minimum = 0.0, .exclusiveMinimum = true, .required = true});
  f.number("angle", &P::angle,
           "Direction of the rectangle's axis, degrees counter-clockwise on screen (axis (cos a, "
           "-sin a)); relative to the relative_to step's rotation.",
           {.minimum = -360.0, .maximum = 360.0});
}

// The rectangle in the live image: the centre through `frame`, the axis turned and the sizes
// scaled as the frame does at the centre.
MeasuringRect placeRect(const cv::Matx33d& frame, cv::Point2d centre, double length, double width,
                        double angleDeg);

// The arc in the live image: the centre through `frame`, the start angle turned and the radius
// and width scaled as the frame does at the centre.
MeasuringArc placeArc(const cv::Matx33d& frame, cv::Point2d centre, double radius,
                      double startAngleDeg, double extentDeg, double width);

// The outline of the arc's band (outer edge, then inner edge back), for the overlay.
std::vector<cv::Point2d> arcOutline(const MeasuringArc& arc);

// The four corners, for the overlay and for inside tests.
std::vector<cv::Point2d> rectCorners(const MeasuringRect& rect);

// Whether `p` lies inside the rectangle.
bool insideRect(const MeasuringRect& rect, cv::Point2d p);

}  // namespace facet::service
