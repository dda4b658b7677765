#pragma once
// `circle`: measures a circle in an annulus around its nominal position.

#include <optional>
#include <string>

#include "algorithms/circle/circle_measure.hpp"
#include "service/engine/table_step.hpp"

namespace facet::service {

struct CircleParams : config::StepParams {
  std::optional<std::string> relativeTo;
  cv::Point2d centre;          // pixels of the relative_to step's reference image
  double nominalDiameter = 0;  // mm
  double searchWidth = 0;      // mm, width of the annulus searched around the nominal circle
  CirclePolarity polarity = CirclePolarity::Any;
};

class CircleStep : public TableStep<CircleParams> {
 public:
  CircleStep();
  [[nodiscard]] StepResult run(const config::Step& step, StepContext& part) const override;

 private:
  void crossCheck(const CircleParams& params, config::StepReading& in) const override;
};

}  // namespace facet::service
