#pragma once
// `distance`: a distance or angle between the results of two earlier steps.

#include <string>

#include "config/step_fields.hpp"
#include "service/engine/step_unit.hpp"

namespace facet::service {

struct DistanceParams : config::StepParams {
  enum class Measure { CentreToCentre, PointToLine, Angle };
  Measure measure = Measure::CentreToCentre;
  std::string from;  // step id: a point (or a line for Angle)
  std::string to;    // step id: a point (CentreToCentre) or a line (PointToLine, Angle)
};

class DistanceStep : public StepUnit {
 public:
  DistanceStep();
  [[nodiscard]] const config::StepKindSpec& format() const override { return format_; }
  [[nodiscard]] config::StepOffers offers() const override { return {}; }
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
