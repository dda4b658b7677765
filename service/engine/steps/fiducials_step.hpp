#pragma once
// `fiducials`: finds round marks near their nominal positions; reports shift and rotation and
// gives the similarity that takes the nominal marks onto the found ones as its pose.

#include <optional>
#include <string>
#include <vector>

#include "algorithms/circle/circle_measure.hpp"
#include "service/engine/table_step.hpp"

namespace facet::service {

struct FiducialsParams : config::StepParams {
  std::optional<std::string> relativeTo;  // id of an earlier pose step
  std::vector<cv::Point2d> marks;         // nominal mark centres, pixels; at least 2
  double markDiameter = 1.0;              // mm
  double searchRadius = 1.0;              // mm around each nominal centre
  CirclePolarity polarity = CirclePolarity::Any;
};

class FiducialsStep : public TableStep<FiducialsParams> {
 public:
  FiducialsStep();
  [[nodiscard]] StepResult run(const config::Step& step, StepContext& part) const override;

 private:
  void crossCheck(const FiducialsParams& params, config::StepReading& in) const override;
};

}  // namespace facet::service
