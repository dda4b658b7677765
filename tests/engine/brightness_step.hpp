#pragma once
// A step kind that exists only in the tests: the mean grey level of a rectangle, 0..1. It shows
// that a kind is one unit: registered beside facet's own kinds, it is checked, described in the
// JSON schema, inspected by facetd and by `facet replay`, and no file of facet knows it.

#include <optional>

#include "service/engine/table_step.hpp"

namespace facet::test {

struct BrightnessParams : config::StepParams {
  std::optional<cv::Rect2d> region;  // pixels of the live image; empty = all of it
};

class BrightnessStep : public service::TableStep<BrightnessParams> {
 public:
  BrightnessStep();
  [[nodiscard]] service::StepResult run(const config::Step& step,
                                        service::StepContext& part) const override;
};

// facet's kinds and BrightnessStep.
config::StepKindRegistry stepsWithBrightness();

}  // namespace facet::test
