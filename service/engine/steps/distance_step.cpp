#include "service/engine/steps/distance_step.hpp"

#include <cmath>

#include "algorithms/geometry/pose2d.hpp"
#include "config/recipe_format.hpp"

namespace facet::service {

using config::Quantity;
using config::StepOffers;
using Measure = DistanceParams::Measure;

namespace {

bool fromIsLine(Measure m) {
  return m == Measure::LineToLine || m == Measure::Angle || m == Measure::Intersection;
}

double cross(cv::Point2d a, cv::Point2d b) {
  return a.x * b.y - a.y * b.x;
}

// The checks a measure gives.
bool gives(Measure m, const std::string& check) {
  switch (m) {
    case Measure::CentreToCentre:
    case Measure::PointToLine:
      return check == "distance";
    case Measure::LineToLine:
      return check == "distance" || check == "angle";
    case Measure::Angle:
    case Measure::Intersection:
      return check == "angle";
  }
  return false;
}

}  // namespace

DistanceStep::DistanceStep() : TableStep({.point = true}) {
  // `from` and `to` are read after `measure`: what they must offer depends on it.
  fields_.choice("measure", &DistanceParams::measure,
                 {{"centre_to_centre", Measure::CentreToCentre},
                  {"point_to_line", Measure::PointToLine},
                  {"line_to_line", Measure::LineToLine},
                  {"angle", Measure::Angle},
                  {"intersection", Measure::Intersection}},
                 "centre_to_centre (two points), point_to_line (`from` a point, `to` a line), "
                 "line_to_line (the distance of `from`'s point from the line `to`, for parallel "
                 "lines their distance, and the angle between them), angle (between two lines), "
                 "intersection (where two lines cross: a point for later steps, and their "
                 "angle). Lines are line steps and the x axes of pose steps.",
                 true);
  fields_.add({.name = "from",
               .type = config::FieldType::StepRef,
               .description = "Id of an earlier step.",
               .required = true},
              [](DistanceParams& d, const YAML::Node&, config::StepReading& in) {
                d.from = in.stepRef("from",
                                    fromIsLine(d.measure) ? &StepOffers::line : &StepOffers::point)
                             .value_or("");
              });
  fields_.add({.name = "to",
               .type = config::FieldType::StepRef,
               .description = "Id of an earlier step.",
               .required = true},
              [](DistanceParams& d, const YAML::Node&, config::StepReading& in) {
                d.to = in.stepRef("to", d.measure == Measure::CentreToCentre ? &StepOffers::point
                                                                             : &StepOffers::line)
                           .value_or("");
              });
  checks_ = {
      "distance checks",
      "",
      {config::checkField("distance", Quantity::Length,
                          "centre_to_centre, point_to_line and line_to_line: the distance.", 0.0),
       config::checkField("angle", Quantity::Angle,
                          "angle, line_to_line and intersection: the angle from `from`'s "
                          "line to `to`'s, counter-clockwise on screen.")}};
  describe("distance",
           "A distance, angle or crossing between the results of two earlier "
           "steps.");
}

void DistanceStep::crossCheck(const DistanceParams& d, config::StepReading& in) const {
  if (!d.from.empty() && d.from == d.to)
    in.error(in["to"], "'from' and 'to' are the same step '" + d.to + "'");
  // The check must be a quantity the measure gives.
  if (const YAML::Node checks = in["checks"]; checks && checks.IsMap() && in["measure"]) {
    for (const auto& entry : checks) {
      const std::string name = entry.first.Scalar();
      if ((name == "angle" || name == "distance") && !gives(d.measure, name))
        in.error(entry.first, "check '" + name + "' does not fit measure '" +
                                  in["measure"].Scalar() + "'; use '" +
                                  (name == "angle" ? "distance" : "angle") + "'");
    }
  }
}

StepResult DistanceStep::run(const config::Step& step, StepContext& part) const {
  const auto& d = step.as<DistanceParams>();
  const StepResult& from = part.done.at(d.from);
  const StepResult& to = part.done.at(d.to);
  // With a lens model and a measuring plane, points and lines are mapped into the plane and the
  // distance or angle computed there, in mm and plane degrees.
  const auto plane = part.calibration.worldMapping();
  const auto where = [&](cv::Point2d p) { return plane ? plane->toPlane(p) : p; };
  const auto back = [&](cv::Point2d p) { return plane ? plane->toImage(p) : p; };
  // A line's direction in the plane: the image direction (cos a, -sin a) mapped through two
  // points 10 px apart; angles stay counter-clockwise as seen on screen.
  const auto direction = [&](cv::Point2d p, double deg) {
    const double a = radians(deg);
    const cv::Point2d dir(std::cos(a), -std::sin(a));
    if (!plane) return dir;
    const cv::Point2d v = plane->toPlane(p + 10.0 * dir) - plane->toPlane(p);
    return v / cv::norm(v);
  };
  // A direction maps into the plane where it lies; without a position, at the image centre.
  const cv::Point2d centre((part.grey.cols - 1) / 2.0, (part.grey.rows - 1) / 2.0);
  const auto angleBetween = [&] {
    const cv::Point2d a = direction(from.point.value_or(centre), *from.angleDeg);
    const cv::Point2d b = direction(to.point.value_or(centre), *to.angleDeg);
    return degrees(wrapAngle(std::atan2(cross(a, b), a.dot(b)) * -1.0));
  };
  // A line is a point and an angle; `angle` needs only the angles.
  const bool fromLine = fromIsLine(d.measure), toLine = d.measure != Measure::CentreToCentre;
  const bool anglesOnly = d.measure == Measure::Angle;
  if ((!anglesOnly && !from.point) || (fromLine && !from.angleDeg))
    return StepResult::failed("step '" + d.from + "' gives no " + (fromLine ? "line" : "position"));
  if ((!anglesOnly && !to.point) || (toLine && !to.angleDeg))
    return StepResult::failed("step '" + d.to + "' gives no " + (toLine ? "line" : "position"));

  StepResult r;
  r.lengthsInMm = plane.has_value();
  const cv::Point2d p = where(from.point.value_or(centre)), q = where(to.point.value_or(centre));
  switch (d.measure) {
    case Measure::CentreToCentre:
      r.values["distance"] = cv::norm(p - q);
      r.point = back((p + q) * 0.5);
      part.overlay.polyline({*from.point, *to.point}, true);
      break;
    case Measure::PointToLine:
    case Measure::LineToLine: {
      // The perpendicular from `from`'s point onto the line `to`.
      const cv::Point2d dir = direction(*to.point, *to.angleDeg);
      const cv::Point2d foot = q + (p - q).dot(dir) * dir;
      r.values["distance"] = std::abs(cross(p - q, dir));
      if (d.measure == Measure::LineToLine) r.values["angle"] = angleBetween();
      r.point = back(foot);
      part.overlay.polyline({*from.point, *r.point}, true);
      break;
    }
    case Measure::Angle:
      r.values["angle"] = angleBetween();
      break;
    case Measure::Intersection: {
      const cv::Point2d a = direction(*from.point, *from.angleDeg);
      const cv::Point2d b = direction(*to.point, *to.angleDeg);
      const double det = cross(a, b);
      // Lines closer than 0.01 degree to parallel cross too far away to mean anything.
      if (std::abs(det) < radians(0.01))
        return StepResult::failed("the lines of '" + d.from + "' and '" + d.to +
                                  "' are parallel: they do not cross");
      const cv::Point2d x = p + (cross(q - p, b) / det) * a;
      r.values["angle"] = angleBetween();
      r.point = back(x);
      part.overlay.cross(*r.point, 6, true);
      break;
    }
  }
  return r;
}

}  // namespace facet::service
