#pragma once
// `distance`: a relation between the results of two earlier steps: the distance of two points, of
// a point from a line, of two (parallel) lines, the angle between two lines, where two lines
// cross. Points come from circle, caliper, blob, line and pose steps; lines from line steps and
// pose steps (their x axis). Its result offers a point: the crossing, the foot of the
// perpendicular, or the middle of the two points.

#include <string>

#include "service/engine/table_step.hpp"

namespace facet::service {

struct DistanceParams : config::StepParams {
  enum class Measure { CentreToCentre, PointToLine, LineToLine, Angle, Intersection };
  Measure measure = Measure::CentreToCentre;
  std::string from;  // step id: a point (CentreToCentre, PointToLine) or a line
  std::string to;    // step id: a point (CentreToCentre) or a line
};

class DistanceStep : public TableStep<DistanceParams> {
 public:
  DistanceStep();
  [[nodiscard]] StepResult run(const config::Step& step, StepContext& part) const override;
  [[nodiscard]] bool needsImage() const override { return false; }

 private:
  void crossCheck(const DistanceParams& params, config::StepReading& in) const override;
};

}  // namespace facet::service
