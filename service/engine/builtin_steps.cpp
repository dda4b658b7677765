#include "service/engine/builtin_steps.hpp"

#include "service/engine/steps/align_step.hpp"
#include "service/engine/steps/blob_step.hpp"
#include "service/engine/steps/caliper_step.hpp"
#include "service/engine/steps/circle_step.hpp"
#include "service/engine/steps/distance_step.hpp"
#include "service/engine/steps/fiducials_step.hpp"
#include "service/engine/steps/line_step.hpp"
#include "service/engine/steps/scan_align_step.hpp"
#include "service/engine/steps/shape_step.hpp"

namespace facet::service {

config::StepKindRegistry builtinSteps() {
  config::StepKindRegistry kinds;
  kinds.add(std::make_unique<AlignStep>());
  kinds.add(std::make_unique<FiducialsStep>());
  kinds.add(std::make_unique<ShapeStep>());
  kinds.add(std::make_unique<CircleStep>());
  kinds.add(std::make_unique<CaliperStep>());
  kinds.add(std::make_unique<LineStep>());
  kinds.add(std::make_unique<BlobStep>());
  kinds.add(std::make_unique<DistanceStep>());
  kinds.add(std::make_unique<ScanAlignStep>());
  return kinds;
}

}  // namespace facet::service
