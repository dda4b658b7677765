#include "service/engine/steps/circle_step.hpp"

#include <cmath>
#include <optional>
#include <string>
#include <vector>

#include "algorithms/calibration/plane_circle.hpp"
#include "algorithms/circle/disc_locator.hpp"
#include "algorithms/registration/register_images.hpp"
#include "config/recipe_format.hpp"
#include "config/yaml_validation.hpp"
#include "service/engine/steps/polarity_names.hpp"
#include "service/engine/steps/pose_fields.hpp"

namespace facet::service {
namespace {

// The rim as the image shows it, for the overlay: 72 points of the circle in the plane mapped
// into the image, or of the ellipse the image measured.
template <typename PointAt>
std::vector<cv::Point2d> rimOutline(PointAt pointAt) {
  std::vector<cv::Point2d> outline;
  for (int i = 0; i < 72; ++i) outline.push_back(pointAt(2.0 * CV_PI * i / 72));
  return outline;
}

std::vector<cv::Point2d> rimOutline(const WorldMapping& plane, const PlaneCircle& c) {
  return rimOutline([&](double t) {
    return plane.toImage(c.centreMm + c.diameterMm / 2 * cv::Point2d(std::cos(t), std::sin(t)));
  });
}

std::vector<cv::Point2d> rimOutline(const CircleMeasurement& m) {
  // The major axis counter-clockwise on screen, y down.
  const double a = m.majorAxisDeg * CV_PI / 180;
  const cv::Point2d major(std::cos(a), -std::sin(a)), minor(-major.y, major.x);
  return rimOutline([&](double t) {
    return m.centre + m.majorDiameter / 2 * std::cos(t) * major +
           m.minorDiameter / 2 * std::sin(t) * minor;
  });
}

}  // namespace

using config::Quantity;

CircleStep::CircleStep() : TableStep({.point = true}) {
  addRelativeTo(fields_);
  fields_.point("centre", &CircleParams::centre,
                "Nominal centre [x, y], pixels of the relative_to step's reference image.", true);
  fields_.number("nominal_diameter", &CircleParams::nominalDiameter, "Nominal diameter, mm.",
                 {.minimum = 0.0, .exclusiveMinimum = true, .required = true});
  fields_.number("search_width", &CircleParams::searchWidth,
                 "Width of the annulus searched around the nominal circle, mm; less than the "
                 "diameter. A circle not found there is looked for within one diameter of its "
                 "nominal centre and measured where it is (its x, y and position report the "
                 "offset).",
                 {.minimum = 0.0, .exclusiveMinimum = true, .required = true});
  fields_.choice("polarity", &CircleParams::polarity, circlePolarityNames(),
                 "Circle darker (a hole) or lighter than its surroundings.");
  checks_ = {"circle checks",
             "",
             {config::checkField("diameter", Quantity::Length, "Fitted diameter.", 0.0),
              config::checkField("x", Quantity::Length, "Centre offset from nominal along x."),
              config::checkField("y", Quantity::Length, "Centre offset from nominal along y."),
              config::checkField("position", Quantity::Length,
                                 "Distance of the centre from its nominal position (true "
                                 "position).",
                                 0.0),
              config::checkField("roundness", Quantity::Length,
                                 "Largest minus smallest radius of the edge points.", 0.0)}};
  describe("circle", "Measures a circle in an annulus around its nominal position.");
}

void CircleStep::crossCheck(const CircleParams& c, config::StepReading& in) const {
  using config::formatNumber;
  if (c.nominalDiameter > 0 && c.searchWidth >= c.nominalDiameter)
    in.error(in["search_width"], "'search_width' " + formatNumber(c.searchWidth) +
                                     " mm must be smaller than 'nominal_diameter' " +
                                     formatNumber(c.nominalDiameter) +
                                     " mm: the search annulus would cover the centre");
}

StepResult CircleStep::run(const config::Step& step, StepContext& part) const {
  const auto& c = step.as<CircleParams>();
  const cv::Point2d expected = mapPoint(part.frameOf(c.relativeTo), c.centre);
  // With a lens model and a measuring plane the rim is mapped into the plane and the circle
  // measured there, in mm; the search annulus uses the plane's scale at the expected centre.
  const auto plane = part.calibration.worldMapping();
  const double scale = plane ? plane->mmPerPixelAt(expected) : part.mmPerPixel();
  CircleMeasureParams p;
  p.centre = expected;
  p.radius = c.nominalDiameter / 2.0 / scale;
  p.width = c.searchWidth / scale;
  p.polarity = c.polarity;
  // With the plane the rim's grey values are fitted there (plane_circle.hpp); the image's own
  // grey-value fit would fit a circle to what a tilted view makes an ellipse, and nothing would
  // use its result: on a 29 px hole at 30 degrees it was two thirds of the image measurement's
  // time (bench_plane_measures).
  p.refineWithGreyValues = !plane;
  CircleMeasurement m = measureCircle(part.grey, p);
  part.overlay.circle(expected, std::max(1.0, p.radius - p.width), true, true);
  part.overlay.circle(expected, p.radius + p.width, true, true);
  std::string note;
  // A hole seen at an angle is an ellipse in the image, which the image measures as one up to
  // about 60 degrees of tilt and refuses beyond (or with a sector of it hidden); the plane judges
  // a refused rim by the same tests and measures it there.
  PlaneCircleVerdict inPlane;
  if (plane) inPlane = measureCircleInPlane(part.grey, m, p, *plane);
  if (!inPlane.circle && !m.status.ok() && m.status.cause != CircleFailure::BadInput &&
      m.status.cause != CircleFailure::AnnulusOutsideImage) {
    // Nothing round in the annulus: a hole drilled off its place is still a hole, and the line
    // must learn how far off it is, not only that the step failed. Look for the disc within one
    // diameter of its nominal place and measure it there; its position check then judges it.
    if (const auto found = locateDisc(part.grey, {.expected = expected,
                                                  .radius = p.radius,
                                                  .searchRadius = 2.0 * p.radius,
                                                  .polarity = c.polarity,
                                                  .minScore = 0.6})) {
      CircleMeasureParams there = p;
      there.centre = found->centre;
      if (CircleMeasurement moved = measureCircle(part.grey, there); moved.status.ok()) {
        m = std::move(moved);
        note = "found off its nominal place";
        if (plane) inPlane = measureCircleInPlane(part.grey, m, there, *plane);
      }
    }
  }
  if (!inPlane.circle && !m.status.ok())
    return StepResult::failed("circle not measured: " + std::string(toString(m.status.cause)) +
                              ": " + m.status.message +
                              (inPlane.refusal.empty() ? "" : " (" + inPlane.refusal + ")"));
  StepResult r;
  r.note = note;
  if (plane) {
    if (!inPlane.circle)
      return StepResult::failed(inPlane.refusal.empty()
                                    ? "circle not measured: its rim does not map into the plane"
                                    : "circle not measured: " + inPlane.refusal);
    const PlaneCircle* w = &*inPlane.circle;
    // Offsets along the plane's axes (the calibration plate's x and y), mm.
    const cv::Point2d nominal = plane->toPlane(expected);
    r.lengthsInMm = true;
    r.values["diameter"] = w->diameterMm;
    r.values["x"] = w->centreMm.x - nominal.x;
    r.values["y"] = w->centreMm.y - nominal.y;
    r.values["position"] = cv::norm(w->centreMm - nominal);
    r.values["roundness"] = w->roundnessMm;
    r.point = plane->toImage(w->centreMm);
    part.overlay.polygon(rimOutline(*plane, *w), true);
  } else {
    // A rim the image shows as an ellipse (a tilted view): its centre is right, its size is not
    // one diameter. The line must learn that its scale holds only on average here.
    if (m.elliptic)
      r.addNote(cv::format(
          "the rim is an ellipse (axes %.2f x %.2f px): the view is tilted; the diameter is that "
          "of a circle of its area (calibrate the measuring plane for the true one)",
          m.majorDiameter, m.minorDiameter));
    r.values["diameter"] = m.diameter;
    r.values["x"] = m.centre.x - expected.x;
    r.values["y"] = m.centre.y - expected.y;
    r.values["position"] = cv::norm(m.centre - expected);
    r.values["roundness"] = m.roundness;
    r.point = m.centre;
    if (m.elliptic)
      part.overlay.polygon(rimOutline(m), true);
    else
      part.overlay.circle(m.centre, m.radius, true);
  }
  // Measured although the sensor clipped the rim (its grey values fitted as clipped): the line
  // should know that the exposure costs it precision.
  if (m.clippedShare > kClippedRimShare)
    r.addNote(
        cv::format("the sensor clipped %.0f%% of the pixels near the rim: fitted as clipped, a few "
                   "hundredths of a pixel less precise; lower the exposure",
                   100.0 * m.clippedShare));
  part.overlay.cross(*r.point, 4, true);
  return r;
}

}  // namespace facet::service
