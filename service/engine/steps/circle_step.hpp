#pragma once
// `circle`: measures a circle in an annulus around its nominal position.

#include <optional>
#include <string>

#include "algorithms/circle/circle_measure.hpp"
#include "config/step_fields.hpp"
#include "service/engine/step_unit.hpp"

namespace facet::service {

struct CircleParams : config::StepParams {
  std::optional<std::string> relativeTo;
  cv::Point2d centre;          // pixels of the relative_to step's reference image
  double nominalDiameter = 0;  // mm
  double searchWidth = 0;      // mm, width of the annulus searched around the nominal circle
  CirclePolarity polarity = CirclePolarity::Any;
};

class CircleStep : public StepUnit {
 public:
  CircleStep();
  [[nodiscard]] const config::StepKindSpec& format() const override { return format_; }
  [[nodiscard]] config::StepOffers offers() const override { return {.point = true}; }
  [[nodiscard]] std::shared_ptr<const config::StepParams> read(
      config::StepReading& in) const override;
  [[nodiscard]] StepResult run(const config::Step& step, StepContext& part) const override;

 private:
  config::StepFields<CircleParams> fields_;
  config::ObjectSpec checks_;
  config::StepKindSpec format_;
};

}  // namespace facet::service
