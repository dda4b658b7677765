#pragma once
// A circle measured in the measuring plane, in mm: the rim's subpixel edge points (from
// CircleMeasure in the image) are mapped into the plane and a circle fitted there, then refined
// with the grey values of the image around the rim, modelled in the plane. A circle seen at an
// angle or through a distorting lens is no circle in the image; in the plane it is.
//
// The edge points of a curved rim sit slightly inside it (second-derivative edges on a blurred
// curve, about k / r with k from the blur); each point is moved outwards by that before mapping:
// k from the blur CircleMeasure's grey-value fit measured for the edge points' circle, the
// default k for the start of the grey-value fit in the plane (which measures the blur itself).

#include <optional>
#include <string>
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
  double coverageDeg = 0;    // angular extent the rim's points cover, in the plane (0 unset)
  bool greyRefined = false;  // centre and diameter from the grey-value fit in the plane
};

// Least-squares (orthogonal distance) circle through plane points; nullopt below 3 points or
// when the fit does not converge.
std::optional<PlaneCircle> fitCircle(const std::vector<cv::Point2d>& points);

// The image measurement's circle in the plane from its edge points; nullopt when the measurement
// failed or its points leave the plane.
std::optional<PlaneCircle> circleInPlane(const CircleMeasurement& measurement,
                                         const WorldMapping& mapping);

// Whether a failed image measurement failed only as a circle in the image: its inliers' coverage
// or RMS, or its fitted circle's place, judged against a circle, which a rim seen at an angle
// is not (an ellipse of 0.87 : 1 at 30 degrees). Its inliers still start a measurement in the
// plane, which judges the rim again there.
bool refusedAsImageCircle(const CircleMeasurement& measurement);

// The image measurement's circle in the plane, measured there: the rim's edge points re-collected
// about the circle in the plane (the image fit's inliers are those near a circle in the image),
// fitted there, then centre and diameter refined with the grey values around the rim, modelled
// in the plane (plane_circle_profile.hpp): the precision of the image's grey-value fit with the
// plane's geometry. Roundness, RMS and coverage are the re-collected edge points'. When the grey
// fit does not converge the edge points' circle is returned (greyRefined false). Takes a
// measurement that succeeded or was refusedAsImageCircle, with or without the image's own
// grey-value fit (its result is not used here); nullopt for others, and when the points leave
// the plane.
std::optional<PlaneCircle> circleInPlane(const cv::Mat& image, const CircleMeasurement& measurement,
                                         const WorldMapping& mapping);

// Why a circle measured in the plane from a rim the image refusedAsImageCircle is refused in the
// plane too, by the image measurement's own tests there: the coverage, the RMS (its pixels at the
// plane's scale at the expected centre) and the search annulus (`params`' centre, radius and
// width carried into the plane). Empty when it passes.
std::string refusalInPlane(const PlaneCircle& circle, const CircleMeasureParams& params,
                           const WorldMapping& mapping);

// What a station with a measuring plane makes of an image measurement of a circle.
struct PlaneCircleVerdict {
  std::optional<PlaneCircle> circle;  // measured in the plane and accepted
  // The image refused the rim as a circle (refusedAsImageCircle), so the plane judged it: it
  // accepted it (circle set) or refused it too (`refusal` says why, when the rim mapped at all).
  bool judgedInPlane = false;
  // Why the plane refused the rim; also, for any measurement, a rim the sensor clipped that the
  // grey values could not fit in the plane (clippedRimRefusal).
  std::string refusal;
};

// The circle of a measurement made with `params`, in the plane: circleInPlane for a measurement
// that succeeded; for one the image refusedAsImageCircle, circleInPlane judged by refusalInPlane.
// No circle for other failures, when the rim does not map into the plane, and when the sensor
// clipped the rim and the grey values could not fit it there (`refusal` says so).
PlaneCircleVerdict measureCircleInPlane(const cv::Mat& image, const CircleMeasurement& measurement,
                                        const CircleMeasureParams& params,
                                        const WorldMapping& mapping);

}  // namespace facet
