#pragma once
// `blob`: the presence, count and area of dark or light blobs (holes, pads, labels, dirt) in a
// rectangle placed on the part.

#include <limits>
#include <optional>
#include <string>

#include "algorithms/measure/blob_analysis.hpp"
#include "service/engine/table_step.hpp"

namespace facet::service {

struct BlobStepParams : config::StepParams {
  std::optional<std::string> relativeTo;
  cv::Point2d centre;  // pixels of the relative_to step's reference image
  double length = 0;   // pixels, along the rectangle's axis
  double width = 0;    // pixels, across it
  double angle = 0;    // degrees, relative to the relative_to step's rotation
  BlobPolarity polarity = BlobPolarity::Dark;
  BlobThreshold threshold = BlobThreshold::Otsu;
  double level = 128.0;   // grey levels (8-bit scale): fixed level or distance from the median
  double minArea = 4.0;   // pixels^2
  double maxArea = 1e12;  // pixels^2
  double minRoundness = 0.0;
  // Whether a region without a blob fails the step (else count and presence are 0).
  bool required = true;
};

class BlobStep : public TableStep<BlobStepParams> {
 public:
  BlobStep();
  [[nodiscard]] StepResult run(const config::Step& step, StepContext& part) const override;

 private:
  void crossCheck(const BlobStepParams& params, config::StepReading& in) const override;
};

}  // namespace facet::service
