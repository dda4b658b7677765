#pragma once
// RecipeInspection: runs one recipe's steps, in order, on one frame, and turns the measured
// values into checks and a verdict.
//
// Positions flow through the steps as homographies: every pose step (align, fiducials, shape)
// yields a map from its reference image's pixels to the live image, and a later step with
// `relative_to` carries its nominal positions through it. Lengths are measured in pixels and
// reported in the unit of each check (mm through the station's calibration).
//
// A step that cannot produce its result (part not found, circle not measurable) fails the part
// and every step that depends on it; the failure names the step and its cause. Only a fault of
// the inspection itself (an exception, a missing live scan) gives Verdict::Error.

#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "algorithms/scan/scan.hpp"
#include "config/recipe.hpp"
#include "service/daemon/overlay.hpp"
#include "service/daemon/part_result.hpp"

namespace facet::service {

struct InspectionInput {
  cv::Mat image;                   // Mono8, Mono16 or BGR8
  std::optional<scan::Scan> scan;  // live range scan, for scan_align steps
};

struct InspectionOutcome {
  Verdict verdict = Verdict::Error;
  std::vector<Measurement> measurements;
  std::vector<std::string> failedChecks;  // "<step>.<check>" or "<step>: <cause>"
  std::string error;                      // set with Verdict::Error
  std::vector<StepTiming> timings;
  double totalMs = 0;
  Overlay overlay;
};

// Copies an inspection's verdict, measurements, failed checks, error and timings into the part
// (facetd's store and the replay report keep the same record of a part).
void recordOutcome(PartResult& part, const InspectionOutcome& outcome);

// A recipe's resources could not be loaded (missing or corrupt image, model or scan).
struct InspectionSetupError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

class RecipeInspection {
 public:
  // Loads every reference image, shape model and reference scan the recipe names. Throws
  // InspectionSetupError naming the file. mmPerPixel > 0.
  RecipeInspection(std::shared_ptr<const config::Recipe> recipe, double mmPerPixel);

  // Never throws: faults become Verdict::Error with the cause. Safe to call from several threads.
  [[nodiscard]] InspectionOutcome inspect(const InspectionInput& input) const;

  [[nodiscard]] const config::Recipe& recipe() const { return *recipe_; }
  [[nodiscard]] std::shared_ptr<const config::Recipe> recipePtr() const { return recipe_; }

  struct Resources;

 private:
  std::shared_ptr<const config::Recipe> recipe_;
  double mmPerPixel_;
  std::shared_ptr<const Resources> resources_;
};

}  // namespace facet::service
