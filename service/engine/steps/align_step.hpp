#pragma once
// `align`: finds the part and gives the pose that later steps' positions follow: log-polar
// registration to a reference image, or a trained shape model.

#include <filesystem>
#include <optional>

#include <opencv2/core.hpp>

#include "config/step_fields.hpp"
#include "service/engine/step_unit.hpp"

namespace facet::service {

struct AlignParams : config::StepParams {
  enum class Method { Registration, Shape };
  Method method = Method::Registration;
  std::filesystem::path reference;         // reference image (registration) or template (shape)
  std::optional<cv::Rect2d> region;        // part of the reference used; empty = all of it
  std::filesystem::path model;             // trained shape model (method shape)
  std::optional<cv::Rect2d> searchRegion;  // where to search in the live image; empty = all
  double minScore = 0.7;                   // 0..1
  config::AngleRange angleRange;
};

class AlignStep : public StepUnit {
 public:
  AlignStep();
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
  config::StepFields<AlignParams> fields_;
  config::ObjectSpec checks_;
  config::StepKindSpec format_;
};

}  // namespace facet::service
