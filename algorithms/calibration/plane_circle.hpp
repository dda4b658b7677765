#pragma once
// A circle measured in the measuring plane, in mm: the rim's subpixel edge points (from
// CircleMeasure in the image) are mapped into the plane and a circle fitted there. A circle seen
// at an angle or through a distorting lens is no circle in the image; in the plane it is.
//
// The edge points of a curved rim sit slightly inside it (second-derivative edges on a blurred
// curve, about k / r with k from the blur that CircleMeasure's grey-value fit measured); each
// point is moved outwards by that before mapping.

#include <optional>
#include <vector>

#include <opencv2/core.hpp>

#include "algorithms/calibration/world_mapping.hpp"
#include "algorithms/circle/circle_measure.hpp"

namespace facet {

struct PlaneCircle {
  cv::Point2d centreMm;
  double diameterMm = 0;
  double rmsMm = 0;  // RMS of the mapped points' distances to the fitted circle
  // Largest minus smallest of those distances (signed): the rim's roundness in the plane. The
  // image's is not: a round hole seen at an angle is an ellipse there.
  double roundnessMm = 0;
  int points = 0;
};

// Least-squares (orthogonal distance) circle through plane points; nullopt below 3 points or
// when the fit does not converge.
std::optional<PlaneCircle> fitCircle(const std::vector<cv::Point2d>& points);

// The image measurement's circle in the plane; nullopt when the measurement failed or its points
// leave the plane.
std::optional<PlaneCircle> circleInPlane(const CircleMeasurement& measurement,
                                         const WorldMapping& mapping);

}  // namespace facet
