#include "service/engine/steps/line_step.hpp"

#include "algorithms/calibration/plane_measures.hpp"
#include "algorithms/measure/line_measure.hpp"
#include "config/recipe_format.hpp"
#include "service/engine/steps/edge_polarity_names.hpp"
#include "service/engine/steps/placed_rect.hpp"
#include "service/engine/steps/pose_fields.hpp"

namespace facet::service {

using config::Quantity;

LineStep::LineStep() : TableStep({.point = true, .line = true}) {
  addRelativeTo(fields_);
  addMeasuringRect(fields_, "Length of the rectangle along the expected line, pixels.",
                   "Width across the line, pixels: the edge is searched over it.");
  fields_.choice("polarity", &LineStepParams::polarity, edgePolarityNames(),
                 "rising (dark to light across the axis, towards (sin a, cos a): for angle 0 "
                 "dark above), falling or any.");
  fields_.number("min_amplitude", &LineStepParams::minAmplitude,
                 "Smallest grey step of an edge point, grey levels (8-bit scale).",
                 {.minimum = 0.0, .exclusiveMinimum = true});
  checks_ = {"line checks",
             "",
             {config::checkField("angle", Quantity::Angle,
                                 "The line's angle in the relative_to step's frame (nominal: the "
                                 "rectangle's angle)."),
              config::checkField("position", Quantity::Length,
                                 "Signed offset of the line from the rectangle's centre, across "
                                 "the axis."),
              config::checkField("straightness", Quantity::Length,
                                 "Largest deviation of an edge point from the fitted line.", 0.0),
              config::checkField("rms", Quantity::Length,
                                 "RMS distance of the edge points from the fitted line.", 0.0)}};
  describe("line", "A straight edge in a rectangle laid along it: angle, straightness, RMS.");
}

StepResult LineStep::run(const config::Step& step, StepContext& part) const {
  const auto& l = step.as<LineStepParams>();
  const MeasuringRect rect =
      placeRect(part.frameOf(l.relativeTo), l.centre, l.length, l.width, l.angle);
  LineMeasureParams p;
  p.polarity = l.polarity;
  p.minAmplitude = l.minAmplitude;
  const LineMeasurement m = measureLine(part.grey, rect, p);
  part.overlay.polygon(rectCorners(rect), true, true);
  if (!m.status.ok()) return StepResult::failed("line not measured: " + m.status.message);

  // With a lens model and a measuring plane, the line is fitted in the plane to its edge points,
  // its angle taken from the axis as the plane sees it, lengths the plane's (plane_measures.hpp).
  const auto plane = part.calibration.worldMapping();
  const auto seen = lineInPlane(rect, m, plane ? &*plane : nullptr);
  if (!seen)
    return StepResult::failed("line not measured: it does not map into the measuring plane");
  // The line's middle: the plane's when it was fitted there.
  const cv::Point2d mid = plane ? plane->toImage((seen->p1 + seen->p2) * 0.5) : (m.p1 + m.p2) * 0.5;

  StepResult r;
  r.lengthsInMm = plane.has_value();
  r.values["angle"] = l.angle + seen->angleFromAxis;
  r.values["position"] = seen->offset;
  r.values["straightness"] = seen->straightness;
  r.values["rms"] = seen->rms;
  r.point = mid;
  r.angleDeg = m.angle;
  if (m.partial) r.note = "part of the line rectangle lies outside the image: measured inside only";
  if (m.clippedPoints > 0)
    r.addNote(
        cv::format("%d of its points lie beside grey values the sensor clipped: the line lies up "
                   "to a pixel towards the unclipped side; lower the exposure",
                   m.clippedPoints));
  part.overlay.polyline({m.p1, m.p2}, true);
  return r;
}

}  // namespace facet::service
