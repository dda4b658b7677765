#include "service/engine/steps/distance_step.hpp"

#include <cmath>

#include "algorithms/geometry/pose2d.hpp"
#include "config/recipe_format.hpp"

namespace facet::service {

using config::Quantity;
using config::StepOffers;
using Measure = DistanceParams::Measure;

DistanceStep::DistanceStep() {
  // `from` and `to` are read in read(): what they must offer depends on `measure`.
  fields_.choice("measure", &DistanceParams::measure,
                 {{"centre_to_centre", Measure::CentreToCentre},
                  {"point_to_line", Measure::PointToLine},
                  {"angle", Measure::Angle}},
                 "centre_to_centre (two points), point_to_line (`from` a point, `to` a pose's x "
                 "axis), angle (between two poses' x axes).",
                 true);
  fields_.add({.name = "from",
               .type = config::FieldType::StepRef,
               .description = "Id of an earlier step.",
               .required = true},
              [](DistanceParams& d, const YAML::Node&, config::StepReading& in) {
                d.from = in.stepRef("from", d.measure == Measure::Angle ? &StepOffers::line
                                                                        : &StepOffers::point)
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
                          "centre_to_centre and point_to_line: the distance.", 0.0),
       config::checkField("angle", Quantity::Angle, "angle: the angle between the two lines.")}};
  format_ = config::stepFormat("distance",
                               "A distance or angle between the results of two earlier steps.",
                               fields_.specs(), checks_);
}

std::shared_ptr<const config::StepParams> DistanceStep::read(config::StepReading& in) const {
  auto d = std::make_shared<DistanceParams>();
  fields_.read(*d, in);
  if (!d->from.empty() && d->from == d->to)
    in.error(in["to"], "'from' and 'to' are the same step '" + d->to + "'");
  // The check must be the quantity the measure gives.
  if (const YAML::Node checks = in["checks"]; checks && checks.IsMap() && in["measure"]) {
    const std::string wanted = d->measure == Measure::Angle ? "angle" : "distance";
    for (const auto& entry : checks) {
      const std::string name = entry.first.Scalar();
      if ((name == "angle" || name == "distance") && name != wanted)
        in.error(entry.first, "check '" + name + "' does not fit measure '" +
                                  in["measure"].Scalar() + "'; use '" + wanted + "'");
    }
  }
  return d;
}

StepResult DistanceStep::run(const config::Step& step, StepContext& part) const {
  const auto& d = step.as<DistanceParams>();
  const StepResult& from = part.done.at(d.from);
  const StepResult& to = part.done.at(d.to);
  StepResult r;
  switch (d.measure) {
    case Measure::CentreToCentre:
      if (!from.point || !to.point) return StepResult::failed("a step gives no position");
      r.values["distance"] = cv::norm(*from.point - *to.point);
      part.overlay.polyline({*from.point, *to.point}, true);
      break;
    case Measure::PointToLine: {
      if (!from.point || !to.point || !to.angleDeg)
        return StepResult::failed("a step gives no line");
      const double a = radians(*to.angleDeg);
      const cv::Point2d dir(std::cos(a), -std::sin(a));
      const cv::Point2d v = *from.point - *to.point;
      r.values["distance"] = std::abs(v.x * dir.y - v.y * dir.x);
      break;
    }
    case Measure::Angle:
      if (!from.angleDeg || !to.angleDeg) return StepResult::failed("a step gives no orientation");
      r.values["angle"] = degrees(wrapAngle(radians(*to.angleDeg - *from.angleDeg)));
      break;
  }
  return r;
}

}  // namespace facet::service
