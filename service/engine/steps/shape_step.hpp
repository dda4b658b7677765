#pragma once
// `shape`: finds a trained shape model and checks count and pose.

#include <filesystem>
#include <optional>
#include <string>

#include "service/engine/table_step.hpp"

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
  double scaleTolerance = 0.02;  // FindParams::refineScaleTolerance
  int maxDeformation = 0;        // FindParams::maxDeformation
};

class ShapeStep : public TableStep<ShapeParams> {
 public:
  ShapeStep();
  [[nodiscard]] std::shared_ptr<const config::StepResources> prepare(
      const config::Step& step, config::StepReading& in) const override;
  [[nodiscard]] std::vector<config::TrainedModel> train(const config::Step& step) const override;
  [[nodiscard]] StepResult run(const config::Step& step, StepContext& part) const override;
  [[nodiscard]] cv::Mat pictureOfPart(const config::Step& step) const override;
};

}  // namespace facet::service
