#pragma once
// `shape`: finds a trained shape model and checks count and pose.

#include <filesystem>
#include <optional>
#include <string>

#include "config/step_fields.hpp"
#include "service/engine/step_unit.hpp"

namespace facet::service {

struct ShapeParams : config::StepParams {
  std::optional<std::string> relativeTo;
  std::filesystem::path templateImage;  // the image the model is trained from
  std::optional<cv::Rect2d> region;     // part of the template; empty = all of it
  std::filesystem::path model;          // trained model file, written by `facet recipe train`
  std::optional<cv::Rect2d> searchRegion;
  double minScore = 0.7;
  int numMatches = 1;
  config::AngleRange angleRange;
  double maxOverlap = 0.5;
};

class ShapeStep : public StepUnit {
 public:
  ShapeStep();
  [[nodiscard]] const config::StepKindSpec& format() const override { return format_; }
  [[nodiscard]] config::StepOffers offers() const override {
    return {.point = true, .pose = true, .line = true};
  }
  [[nodiscard]] std::shared_ptr<const config::StepParams> read(
      config::StepReading& in) const override;
  [[nodiscard]] std::shared_ptr<const config::StepResources> prepare(
      const config::Step& step, config::StepReading& in) const override;
  [[nodiscard]] std::vector<config::TrainedModel> train(const config::Step& step) const override;
  [[nodiscard]] StepResult run(const config::Step& step, StepContext& part) const override;

 private:
  config::StepFields<ShapeParams> fields_;
  config::ObjectSpec checks_;
  config::StepKindSpec format_;
};

}  // namespace facet::service
