#pragma once
// `align`: finds the part and gives the pose that later steps' positions follow: log-polar
// registration to a reference image, or a trained shape model.

#include <filesystem>
#include <optional>

#include <opencv2/core.hpp>

#include "service/engine/table_step.hpp"

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

class AlignStep : public TableStep<AlignParams> {
 public:
  AlignStep();
  [[nodiscard]] std::shared_ptr<const config::StepResources> prepare(
      const config::Step& step, config::StepReading& in) const override;
  [[nodiscard]] std::vector<config::TrainedModel> train(const config::Step& step) const override;
  [[nodiscard]] StepResult run(const config::Step& step, StepContext& part) const override;
  [[nodiscard]] cv::Mat pictureOfPart(const config::Step& step) const override;

 private:
  void crossCheck(const AlignParams& params, config::StepReading& in) const override;
};

}  // namespace facet::service
