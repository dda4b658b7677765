#include "tests/engine/brightness_step.hpp"

#include "config/recipe_format.hpp"
#include "service/engine/builtin_steps.hpp"
#include "service/engine/frame_maps.hpp"

namespace facet::test {

BrightnessStep::BrightnessStep() : TableStep({}) {
  fields_.rect("region", &BrightnessParams::region,
               "[x, y, width, height] of the live image, pixels; default: all of it.");
  checks_ = {"brightness checks",
             "",
             {config::checkField("level", config::Quantity::Score,
                                 "Mean grey level of the region, 0 (black) .. 1 (white).", 0.0)}};
  describe("brightness", "Mean grey level of a region (a test-only kind).");
}

service::StepResult BrightnessStep::run(const config::Step& step,
                                        service::StepContext& part) const {
  const cv::Rect region = service::clampRect(step.as<BrightnessParams>().region, part.grey.size());
  if (region.empty()) return service::StepResult::failed("region outside the image");
  const double full = part.grey.depth() == CV_16U ? 65535.0 : 255.0;
  service::StepResult r;
  r.values["level"] = cv::mean(part.grey(region))[0] / full;
  part.overlay.polygon(service::outerCorners(region), true, true);
  return r;
}

config::StepKindRegistry stepsWithBrightness() {
  auto kinds = service::builtinSteps();
  kinds.add(std::make_unique<BrightnessStep>());
  return kinds;
}

}  // namespace facet::test
