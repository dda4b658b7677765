#pragma once
// A step kind that exists only in the tests: the mean grey level of a rectangle, 0..1. It shows
// that a kind is one unit: registered beside facet's own kinds, it is checked, described in the
// JSON schema, inspected by facetd and by `facet replay`, and no file of facet knows it.

#include <optional>

#include "config/step_fields.hpp"
#include "service/engine/step_unit.hpp"

namespace facet::test {

struct BrightnessParams : config::StepParams {
  std::optional<cv::Rect2d> region;  // pixels of the live image; empty = all of it
};

class BrightnessStep : public service::StepUnit {
 public:
  BrightnessStep();
  [[nodiscard]] const config::StepKindSpec& format() const override { return format_; }
  [[nodiscard]] config::StepOffers offers() const override { return {}; }
  [[nodiscard]] std::shared_ptr<const config::StepParams> read(
      config::StepReading& in) const override;
  [[nodiscard]] service::StepResult run(const config::Step& step,
                                        service::StepContext& part) const override;

 private:
  config::StepFields<BrightnessParams> fields_;
  config::ObjectSpec checks_;
  config::StepKindSpec format_;
};

// facet's kinds and BrightnessStep.
config::StepKindRegistry stepsWithBrightness();

}  // namespace facet::test
