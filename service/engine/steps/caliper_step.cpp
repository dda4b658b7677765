#include "service/engine/steps/caliper_step.hpp"

#include "config/recipe_format.hpp"
#include "service/engine/steps/edge_polarity_names.hpp"
#include "service/engine/steps/placed_rect.hpp"
#include "service/engine/steps/pose_fields.hpp"

namespace facet::service {

using config::Quantity;
using Measure = CaliperStepParams::Measure;

CaliperStep::CaliperStep() {
  addRelativeTo(fields_);
  addMeasuringRect(fields_, "Length of the rectangle along the measuring axis, pixels.",
                   "Width across the axis, pixels: the grey profile is averaged over it.");
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
  format_ = config::stepFormat(
      "caliper", "Edges or edge pairs along a rectangle: positions, widths, counts and spacing.",
      fields_.specs(), checks_);
}

std::shared_ptr<const config::StepParams> CaliperStep::read(config::StepReading& in) const {
  auto c = std::make_shared<CaliperStepParams>();
  fields_.read(*c, in);
  if (const YAML::Node checks = in["checks"];
      checks && checks.IsMap() && checks["width"] && c->measure != Measure::Pairs)
    in.error(checks["width"], "check 'width' needs 'measure: pairs'");
  return c;
}

StepResult CaliperStep::run(const config::Step& step, StepContext& part) const {
  const auto& c = step.as<CaliperStepParams>();
  const MeasuringRect rect =
      placeRect(part.frameOf(c.relativeTo), c.centre, c.length, c.width, c.angle);
  const MeasuringPath path(rect);
  CaliperParams p;
  p.polarity = c.polarity;
  p.select = c.select;
  p.minAmplitude = c.minAmplitude;
  p.pairs = c.measure == Measure::Pairs;
  const CaliperResult m = measureCaliper(part.grey, path, p);
  part.overlay.polygon(rectCorners(rect), true, true);
  if (!m.ok()) return StepResult::failed("caliper not measured: " + m.message);

  // Where each selected edge or pair lies on the axis, and the pairs' end points.
  std::vector<cv::Point2d> points;
  std::vector<std::pair<cv::Point2d, cv::Point2d>> ends;
  if (p.pairs) {
    for (const CaliperPair& pr : m.pairs) {
      points.push_back(pr.centre);
      ends.emplace_back(pr.first.point, pr.second.point);
    }
  } else {
    for (const CaliperEdge& e : m.edges) points.push_back(e.point);
  }
  // With a lens model and a measuring plane, positions and widths are measured in the plane, in
  // mm, along the axis as the plane sees it.
  const auto plane = part.calibration.worldMapping();
  const cv::Point2d centre(rect.cx, rect.cy);
  const auto where = [&](cv::Point2d q) { return plane ? plane->toPlane(q) : q; };
  cv::Point2d axis = where(centre + path.axisAt(0)) - where(centre);
  axis /= cv::norm(axis);
  const auto position = [&](cv::Point2d q) { return (where(q) - where(centre)).dot(axis); };

  StepResult r;
  r.lengthsInMm = plane.has_value();
  r.values["count"] = static_cast<double>(points.size());
  r.values["position"] = position(points.front());
  if (!ends.empty()) r.values["width"] = cv::norm(where(ends[0].second) - where(ends[0].first));
  if (points.size() >= 2)
    r.values["spacing"] = (position(points.back()) - position(points.front())) /
                          static_cast<double>(points.size() - 1);
  r.point = points.front();
  if (m.partial) r.note = "part of the caliper lies outside the image: measured inside only";

  // Each edge as a short line across the rectangle; pair centres as crosses.
  const double half = rect.width / 2;
  if (!p.pairs)
    for (const CaliperEdge& e : m.edges)
      part.overlay.polyline({path.at(e.position, -half), path.at(e.position, half)}, true);
  for (const CaliperPair& pr : m.pairs) {
    for (const CaliperEdge* e : {&pr.first, &pr.second})
      part.overlay.polyline({path.at(e->position, -half), path.at(e->position, half)}, true);
    part.overlay.cross(pr.centre, 3, true);
  }
  return r;
}

}  // namespace facet::service
