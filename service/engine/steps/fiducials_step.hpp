#pragma once
// `fiducials`: finds round marks near their nominal positions; reports shift and rotation and
// gives the similarity that takes the nominal marks onto the found ones as its pose.

#include <optional>
#include <string>
#include <vector>

#include "algorithms/circle/circle_measure.hpp"
#include "config/step_fields.hpp"
#include "service/engine/step_unit.hpp"

namespace facet::service {

struct FiducialsParams : config::StepParams {
  std::optional<std::string> relativeTo;  // id of an earlier pose step
  std::vector<cv::Point2d> marks;         // nominal mark centres, pixels; at least 2
  double markDiameter = 1.0;              // mm
  double searchRadius = 1.0;              // mm around each nominal centre
  CirclePolarity polarity = CirclePolarity::Any;
};

class FiducialsStep : public StepUnit {
 public:
  FiducialsStep();
  [[nodiscard]] const config::StepKindSpec& format() const override { return format_; }
  [[nodiscard]] config::StepOffers offers() const override {
    return {.point = true, .pose = true, .line = true};
  }
  [[nodiscard]] std::shared_ptr<const config::StepParams> read(
      config::StepReading& in) const override;
  [[nodiscard]] StepResult run(const config::Step& step, StepContext& part) const override;

 private:
  config::StepFields<FiducialsParams> fields_;
  config::ObjectSpec checks_;
  config::StepKindSpec format_;
};

}  // namespace facet::service
