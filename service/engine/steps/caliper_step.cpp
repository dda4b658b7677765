#include "service/engine/steps/caliper_step.hpp"

#include <cmath>

#include "algorithms/calibration/plane_measures.hpp"
#include "config/recipe_format.hpp"
#include "service/engine/steps/edge_polarity_names.hpp"
#include "service/engine/steps/placed_rect.hpp"
#include "service/engine/steps/pose_fields.hpp"

namespace facet::service {

using config::Quantity;
using Measure = CaliperStepParams::Measure;

CaliperStep::CaliperStep() : TableStep({.point = true}) {
  addRelativeTo(fields_);
  // A rectangle (length, angle) or an arc (radius, start_angle, extent): crossCheck() wants one.
  fields_.point("centre", &CaliperStepParams::centre,
                "Centre [x, y] of the rectangle or of the arc's circle, pixels of the relative_to "
                "step's reference image.",
                true);
  fields_.number("length", &CaliperStepParams::length,
                 "Rectangle: its length along the measuring axis, pixels (or give 'radius' for an "
                 "arc).",
                 {.minimum = 0.0, .exclusiveMinimum = true});
  fields_.number("width", &CaliperStepParams::width,
                 "Width across the axis (radially on an arc), pixels: the grey profile is "
                 "averaged over it.",
                 {.minimum = 0.0, .exclusiveMinimum = true, .required = true});
  fields_.number("angle", &CaliperStepParams::angle,
                 "Rectangle: direction of its axis, degrees counter-clockwise on screen (axis "
                 "(cos a, -sin a)); relative to the relative_to step's rotation.",
                 {.minimum = -360.0, .maximum = 360.0});
  fields_.number("radius", &CaliperStepParams::radius,
                 "Arc: radius of the circle the caliper follows, pixels. Edges it finds are "
                 "radial lines crossing it (teeth, slots around a hub); positions, widths and "
                 "spacing are lengths along the arc.",
                 {.minimum = 0.0, .exclusiveMinimum = true});
  fields_.number("start_angle", &CaliperStepParams::startAngle,
                 "Arc: where it begins, degrees counter-clockwise on screen from +x; relative to "
                 "the relative_to step's rotation.",
                 {.minimum = -360.0, .maximum = 360.0});
  fields_.number("extent", &CaliperStepParams::extent,
                 "Arc: its length in degrees, counter-clockwise (negative: clockwise); the "
                 "measuring axis runs that way.",
                 {.minimum = -360.0, .maximum = 360.0});
  fields_.choice("measure", &CaliperStepParams::measure,
                 {{"edges", Measure::Edges}, {"pairs", Measure::Pairs}},
                 "edges (single edges) or pairs (neighbouring edges of opposite polarity: a "
                 "bar's or a slot's width).");
  fields_.choice("polarity", &CaliperStepParams::polarity, edgePolarityNames(),
                 "rising (dark to light along the axis), falling or any; with pairs, the first "
                 "edge's.");
  fields_.choice("select", &CaliperStepParams::select, edgeSelectNames(),
                 "Which edges (or pairs) count: all, first, last or strongest.");
  fields_.number("min_amplitude", &CaliperStepParams::minAmplitude,
                 "Smallest grey step of an edge, grey levels (8-bit scale).",
                 {.minimum = 0.0, .exclusiveMinimum = true});
  checks_ = {
      "caliper checks",
      "",
      {config::checkField("position", Quantity::Length,
                          "Signed distance of the first selected edge (or pair centre) from "
                          "the rectangle's centre along its axis."),
       config::checkField("width", Quantity::Length,
                          "measure: pairs: the first selected pair's width.", 0.0),
       config::checkField(
           "count", Quantity::Count,
           "Number of selected edges (or pairs); none fails the step with that cause.", 0.0),
       config::checkField("spacing", Quantity::Length,
                          "Mean distance between neighbouring selected edges (or pair centres); "
                          "needs two.",
                          0.0)}};
  describe("caliper",
           "Edges or edge pairs along a rectangle: positions, widths, counts and spacing.");
}

void CaliperStep::crossCheck(const CaliperStepParams& c, config::StepReading& in) const {
  if (in["radius"] && in["length"])
    in.error(in["radius"], "'radius' (an arc) and 'length' (a rectangle) exclude each other");
  else if (!in["radius"] && !in["length"])
    in.error(in.node(), "caliper needs 'length' (a rectangle) or 'radius' (an arc)");
  if (in["radius"]) {
    if (in["angle"])
      in.error(in["angle"], "'angle' turns a rectangle; an arc begins at 'start_angle'");
    if (!in["extent"]) in.error(in["radius"], "an arc needs 'extent' (degrees)");
    if (in["extent"] && c.extent && *c.extent == 0.0)
      in.error(in["extent"], "'extent' must not be 0");
  } else {
    for (const char* key : {"start_angle", "extent"})
      if (in[key]) in.error(in[key], std::string("'") + key + "' needs 'radius' (an arc)");
  }
  if (const YAML::Node checks = in["checks"];
      checks && checks.IsMap() && checks["width"] && c.measure != Measure::Pairs)
    in.error(checks["width"], "check 'width' needs 'measure: pairs'");
}

StepResult CaliperStep::run(const config::Step& step, StepContext& part) const {
  const auto& c = step.as<CaliperStepParams>();
  const cv::Matx33d frame = part.frameOf(c.relativeTo);
  std::optional<MeasuringRect> rect;
  std::optional<MeasuringArc> arc;
  if (c.radius)
    arc = placeArc(frame, c.centre, *c.radius, c.startAngle.value_or(0.0), c.extent.value_or(0.0),
                   c.width);
  else
    rect = placeRect(frame, c.centre, c.length.value_or(0.0), c.width, c.angle);
  const MeasuringPath path = arc ? MeasuringPath(*arc) : MeasuringPath(*rect);
  CaliperParams p;
  p.polarity = c.polarity;
  p.select = c.select;
  p.minAmplitude = c.minAmplitude;
  p.pairs = c.measure == Measure::Pairs;
  const CaliperResult m = measureCaliper(part.grey, path, p);
  part.overlay.polygon(arc ? arcOutline(*arc) : rectCorners(*rect), true, true);
  if (!m.status.ok()) return StepResult::failed("caliper not measured: " + m.status.message);

  // Lengths along the axis, from its middle: in the measuring plane, in mm, when the station has
  // a lens model and a plane (plane_measures.hpp).
  const auto plane = part.calibration.worldMapping();
  const WorldMapping* mapping = plane ? &*plane : nullptr;
  const auto span = [&](double s0, double s1) { return spanInPlane(path, mapping, s0, s1); };

  // Where each selected edge or pair lies on the axis (s), and the pairs' ends. A pair's middle
  // is the plane's: halfway between its edges there.
  std::vector<double> along;
  std::vector<cv::Point2d> points;
  std::vector<std::pair<double, double>> ends;
  if (p.pairs) {
    for (const CaliperPair& pr : m.pairs) {
      const double mid = midpointInPlane(path, mapping, pr.first.position, pr.second.position);
      if (!std::isfinite(mid))
        return StepResult::failed(
            "caliper not measured: its axis does not map into the measuring plane");
      along.push_back(mid);
      points.push_back(path.at(mid, 0.0));  // without a plane: the pair's own centre
      ends.emplace_back(pr.first.position, pr.second.position);
    }
  } else {
    for (const CaliperEdge& e : m.edges) {
      along.push_back(e.position);
      points.push_back(e.point);
    }
  }

  StepResult r;
  r.lengthsInMm = plane.has_value();
  r.values["count"] = static_cast<double>(points.size());
  r.values["position"] = span(0.0, along.front());
  if (!ends.empty()) r.values["width"] = span(ends[0].first, ends[0].second);
  if (along.size() >= 2)
    r.values["spacing"] = span(along.front(), along.back()) / static_cast<double>(along.size() - 1);
  r.point = points.front();
  if (m.partial) r.note = "part of the caliper lies outside the image: measured inside only";
  // An edge beside grey values the sensor clipped lies up to a pixel off (CaliperEdge::clipped).
  bool clipped = false;
  for (const CaliperEdge& e : m.edges) clipped = clipped || e.clipped;
  for (const CaliperPair& pr : m.pairs) clipped = clipped || pr.first.clipped || pr.second.clipped;
  if (clipped)
    r.addNote(
        "the sensor clipped the grey values beside an edge: it lies up to a pixel towards the "
        "unclipped side; lower the exposure");

  // Each edge as a short line across the axis; pair centres as crosses.
  const double half = path.width() / 2;
  if (!p.pairs)
    for (const CaliperEdge& e : m.edges)
      part.overlay.polyline({path.at(e.position, -half), path.at(e.position, half)}, true);
  for (const CaliperPair& pr : m.pairs)
    for (const CaliperEdge* e : {&pr.first, &pr.second})
      part.overlay.polyline({path.at(e->position, -half), path.at(e->position, half)}, true);
  if (p.pairs)
    for (const cv::Point2d& centre : points) part.overlay.cross(centre, 3, true);
  return r;
}

}  // namespace facet::service
