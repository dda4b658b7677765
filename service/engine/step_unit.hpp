#pragma once
// StepUnit: one kind of recipe step, whole. Its parameters and their table, reading and
// preparing (config::StepKind), and run(): what it does on one part. A new kind is its own files
// in service/engine/steps/ (usually a TableStep, table_step.hpp) plus one line in
// builtin_steps.cpp; nothing else changes (docs/architecture.md walks through it).
//
// What steps give and how later steps use it (the contract between units):
// - A step whose result has a pose (offers().pose: align, fiducials, shape) sets refToImage, the
//   map from its reference frame into the live image. The frame of an align step is its
//   reference image's pixels; a shape match maps p - r, r the model's reference point in
//   reference pixels; a fiducials step's frame is that of its nominal marks. A later step with
//   `relative_to` writes its positions in that frame (StepContext::frameOf), and its angle range
//   is relative to that step's angle.
// - A step with a position (offers().point) sets `point`; one with a line (offers().line) sets
//   `point` and `angleDeg`: the line runs through the point along that angle.
// - Position checks (x, y, position) are offsets from nominal in the live image's axes.
// - Lengths are pixels; the engine turns them into each check's unit with the station's
//   calibration (a unit that measures in mm sets lengthsInMm).

#include <map>
#include <optional>
#include <string>

#include <opencv2/core.hpp>

#include "algorithms/scan/scan.hpp"
#include "config/recipe.hpp"
#include "config/station_config.hpp"
#include "service/engine/overlay.hpp"
#include "service/engine/step_result.hpp"

namespace facet::service {

// What a step sees of the part being inspected.
struct StepContext {
  const cv::Mat& grey;                            // the frame, 8 or 16 bit, one channel
  const std::optional<scan::Scan>& scan;          // the live range scan, for scan steps
  const config::Calibration& calibration;         // the station's
  const std::map<std::string, StepResult>& done;  // results of the earlier steps, by id
  Overlay& overlay;                               // what the step draws on the part's image

  [[nodiscard]] double mmPerPixel() const { return calibration.mmPerPixel; }
  // The map from the frame of step `relativeTo` to the live image (identity without one).
  [[nodiscard]] cv::Matx33d frameOf(const std::optional<std::string>& relativeTo) const {
    return relativeTo ? *done.at(*relativeTo).refToImage : cv::Matx33d::eye();
  }
};

class StepUnit : public config::StepKind {
 public:
  // Runs the step on one part. Never called when a step in step.inputs failed. A cause of
  // failure is a result (StepResult::failed), not an exception; an exception is a fault of the
  // inspection and makes the part's verdict Error. Safe to call from several threads.
  [[nodiscard]] virtual StepResult run(const config::Step& step, StepContext& part) const = 0;
  // Whether the step measures on the camera image (false: on the range scan).
  [[nodiscard]] virtual bool needsImage() const { return true; }
  // A picture of the part as the step was taught it (an align step's reference image, a shape
  // step's template unless the step is placed relative to another), in the frame later steps
  // place their positions in; empty when the step has none. warmUp() runs the recipe on it
  // before the first part.
  [[nodiscard]] virtual cv::Mat pictureOfPart(const config::Step& /*step*/) const { return {}; }
};

}  // namespace facet::service
