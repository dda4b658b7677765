#pragma once
// `scan_align`: registers a live 2D range scan to a reference scan; reports the pose offset
// that takes the live scan onto the reference scan's frame (x, y in mm, angle in degrees).

#include <filesystem>

#include "service/engine/table_step.hpp"

namespace facet::service {

struct ScanAlignParams : config::StepParams {
  enum class Method { Icp, Dcp, Idcp };
  std::filesystem::path reference;  // CSV scan, rows "x,y" in metres
  Method method = Method::Dcp;
  int maxIterations = 50;
  double maxDistance = 5.0;  // mm, correspondences farther apart are ignored
};

class ScanAlignStep : public TableStep<ScanAlignParams> {
 public:
  ScanAlignStep();
  [[nodiscard]] std::shared_ptr<const config::StepResources> prepare(
      const config::Step& step, config::StepReading& in) const override;
  [[nodiscard]] StepResult run(const config::Step& step, StepContext& part) const override;
  [[nodiscard]] bool needsImage() const override { return false; }
};

}  // namespace facet::service
