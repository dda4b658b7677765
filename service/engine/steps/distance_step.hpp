#pragma once
// `distance`: a relation between the results of two earlier steps: the distance of two points, of
// a point from a line, of two (parallel) lines, the angle between two lines, where two lines
// cross. Points come from circle, caliper, blob, line and pose steps; lines from line steps and
// pose steps (their x axis). Its result offers a point: the crossing, the foot of the
// perpendicular, or the middle of the two points.

#include <string>

#include "config/step_fields.hpp"
#include "service/engine/step_unit.hpp"

namespace facet::service {

struct DistanceParams : config::StepParams {
  enum class Measure { CentreToCentre, PointToLine, LineToLine, Angle, Intersection };
  Measure measure = Measure::CentreToCentre;
  std::string from;  // step id: a point (CentreToCentre, PointToLine) or a line
  std::string to;    // step id: a point (CentreToCentre) or a line
};

class DistanceStep : public StepUnit {
 public:
  DistanceStep();
  [[nodiscard]] const config::StepKindSpec& format() const override { return format_; }
  [[nodiscard]] config::StepOffers offers() const override { return {.point = true}; }
  [[nodiscard]] std::shared_ptr<const config::StepParams> read(
      config::StepReading& in) const override;
  [[nodiscard]] StepResult run(const config::Step& step, StepContext& part) const override;
  [[nodiscard]] bool needsImage() const override { return false; }

 private:
  config::StepFields<DistanceParams> fields_;
  config::ObjectSpec checks_;
  config::StepKindSpec format_;
};

}  // namespace facet::service
