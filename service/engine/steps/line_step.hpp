#pragma once
// `line`: a straight edge measured in a rectangle laid along it: its angle, straightness, RMS
// and offset; the line is offered to later steps (distance: point_to_line, line_to_line, angle,
// intersection).

#include <optional>
#include <string>

#include "algorithms/measure/caliper.hpp"
#include "config/step_fields.hpp"
#include "service/engine/step_unit.hpp"

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

class LineStep : public StepUnit {
 public:
  LineStep();
  [[nodiscard]] const config::StepKindSpec& format() const override { return format_; }
  [[nodiscard]] config::StepOffers offers() const override { return {.point = true, .line = true}; }
  [[nodiscard]] std::shared_ptr<const config::StepParams> read(
      config::StepReading& in) const override;
  [[nodiscard]] StepResult run(const config::Step& step, StepContext& part) const override;

 private:
  config::StepFields<LineStepParams> fields_;
  config::ObjectSpec checks_;
  config::StepKindSpec format_;
};

}  // namespace facet::service
