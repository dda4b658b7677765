#pragma once
// `line`: a straight edge measured in a rectangle laid along it: its angle, straightness, RMS
// and offset; the line is offered to later steps (distance: point_to_line, line_to_line, angle,
// intersection).

#include <optional>
#include <string>

#include "algorithms/measure/caliper.hpp"
#include "service/engine/table_step.hpp"

namespace facet::service {

struct LineStepParams : config::StepParams {
  std::optional<std::string> relativeTo;
  cv::Point2d centre;  // pixels of the relative_to step's reference image
  double length = 0;   // pixels, along the expected line
  double width = 0;    // pixels, across it: where the edge is searched
  double angle = 0;    // degrees, relative to the relative_to step's rotation
  EdgePolarity polarity = EdgePolarity::Any;
  double minAmplitude = 20.0;  // grey levels (8-bit scale)
};

class LineStep : public TableStep<LineStepParams> {
 public:
  LineStep();
  [[nodiscard]] StepResult run(const config::Step& step, StepContext& part) const override;
};

}  // namespace facet::service
