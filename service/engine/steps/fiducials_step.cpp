#include "service/engine/steps/fiducials_step.hpp"

#include <cmath>

#include "algorithms/calibration/plane_circle.hpp"
#include "algorithms/circle/disc_locator.hpp"
#include "algorithms/geometry/pose2d.hpp"
#include "algorithms/geometry/similarity_fit.hpp"
#include "algorithms/registration/register_images.hpp"
#include "config/recipe_format.hpp"
#include "service/engine/steps/polarity_names.hpp"
#include "service/engine/steps/pose_fields.hpp"
#include "service/engine/steps/pose_offset.hpp"

namespace facet::service {
namespace {

using config::Quantity;

}  // namespace

FiducialsStep::FiducialsStep() : TableStep({.point = true, .pose = true, .line = true}) {
  addRelativeTo(fields_);
  fields_.points("marks", &FiducialsParams::marks,
                 "Nominal mark centres [x, y], pixels; at least two.", 2);
  fields_.number("mark_diameter", &FiducialsParams::markDiameter, "Diameter of a mark, mm.",
                 {.minimum = 0.0, .exclusiveMinimum = true, .required = true});
  fields_.number("search_radius", &FiducialsParams::searchRadius,
                 "How far from its nominal centre a mark is searched, mm.",
                 {.minimum = 0.0, .exclusiveMinimum = true});
  fields_.choice("polarity", &FiducialsParams::polarity, circlePolarityNames(),
                 "Marks darker or lighter than their surroundings.");
  checks_ = {
      "fiducials checks",
      "",
      {config::checkField("x", Quantity::Length,
                          "Shift of the marks' centroid along x (the plane's, measured there, "
                          "when the station has a lens model and a plane)."),
       config::checkField("y", Quantity::Length,
                          "Shift of the marks' centroid along y (likewise)."),
       config::checkField("angle", Quantity::Angle,
                          "Rotation of the marks, degrees (in the measuring plane when the "
                          "station has one)."),
       config::checkField("spacing", Quantity::Length,
                          "Distance between the first two marks (in the measuring plane when "
                          "the station has one).",
                          0.0)}};
  describe("fiducials", "Finds round marks near their nominal positions.");
}

void FiducialsStep::crossCheck(const FiducialsParams& f, config::StepReading& in) const {
  for (std::size_t i = 0; i < f.marks.size(); ++i)
    for (std::size_t j = 0; j < i; ++j)
      if (cv::norm(f.marks[i] - f.marks[j]) < 1e-9)
        in.error(in["marks"][i],
                 "mark " + std::to_string(i + 1) + " lies on mark " + std::to_string(j + 1));
}

StepResult FiducialsStep::run(const config::Step& step, StepContext& part) const {
  const auto& f = step.as<FiducialsParams>();
  const cv::Matx33d H = part.frameOf(f.relativeTo);
  // With a lens model and a plane each mark is measured there, as the circle step measures a
  // circle: a round mark seen at an angle is an ellipse in the image, and the image's circle fit
  // keeps the arc a circle matches, off to one side. On the tests' camera at 30 degrees the
  // centre of a 4 mm mark measured in the image lay 4-6 px (about 1 mm) from the image of its
  // true centre; measured in the plane, within 0.001 mm.
  const auto plane = part.calibration.worldMapping();
  std::vector<cv::Point2d> nominal, found, foundMm;  // foundMm: the marks' centres in the plane
  for (const auto& mark : f.marks) {
    const cv::Point2d expected = mapPoint(H, mark);
    const double scale = plane ? plane->mmPerPixelAt(expected) : part.mmPerPixel();
    const double radius = f.markDiameter / 2.0 / scale;
    const double searchRadius = f.searchRadius / scale;
    part.overlay.circle(expected, searchRadius + radius, true, true);
    const std::string where =
        "mark at (" + std::to_string(mark.x) + ", " + std::to_string(mark.y) + ")";
    // Coarse location first: the search radius is usually larger than the mark.
    const auto coarse = locateDisc(part.grey, {.expected = expected,
                                               .radius = radius,
                                               .searchRadius = searchRadius,
                                               .polarity = f.polarity});
    if (!coarse) return StepResult::failed(where + " not found within the search radius");
    CircleMeasureParams p;
    p.centre = coarse->centre;
    p.radius = radius;
    p.width = std::max(2.0, 0.35 * radius);
    p.polarity = f.polarity;
    p.refineWithGreyValues = !plane;  // the plane's grey fit measures it (circle_step.cpp)
    const CircleMeasurement m = measureCircle(part.grey, p);
    if (!plane) {
      if (!m.status.ok())
        return StepResult::failed(where +
                                  " not measured: " + std::string(toString(m.status.cause)));
      part.overlay.circle(m.centre, m.radius, true);
      found.push_back(m.centre);
    } else {
      const PlaneCircleVerdict inPlane = measureCircleInPlane(part.grey, m, p, *plane);
      if (!inPlane.circle)
        return StepResult::failed(
            where + " not measured: " +
            (m.status.ok() ? (inPlane.refusal.empty()
                                  ? std::string("its rim does not map into the measuring plane")
                                  : inPlane.refusal)
                           : std::string(toString(m.status.cause)) +
                                 (inPlane.refusal.empty() ? "" : " (" + inPlane.refusal + ")")));
      // The image point of the mark's centre in the plane: the pose is fitted in the image.
      foundMm.push_back(inPlane.circle->centreMm);
      const cv::Point2d centre = plane->toImage(foundMm.back());
      part.overlay.circle(centre, inPlane.circle->diameterMm / 2 / scale, true);
      found.push_back(centre);
    }
    nominal.push_back(expected);
  }
  const auto similarity = fitSimilarity(nominal, found);
  if (!similarity) return StepResult::failed("the nominal fiducial positions coincide");
  const cv::Matx33d S = similarity->H;
  StepResult r;
  r.refToImage = S * H;
  cv::Point2d cn, cf;
  for (std::size_t i = 0; i < found.size(); ++i) cn += nominal[i], cf += found[i];
  cn *= 1.0 / nominal.size();
  cf *= 1.0 / found.size();
  r.angleDeg = degrees(std::atan2(-S(1, 0), S(0, 0)));
  if (!setPoseOffset(r, plane, cn, cf, *r.angleDeg))
    return StepResult::failed("the fiducials do not map into the measuring plane");
  r.values["spacing"] = plane ? cv::norm(foundMm[1] - foundMm[0]) : cv::norm(found[1] - found[0]);
  r.point = cf;
  return r;
}

}  // namespace facet::service
