#pragma once
// The inspection engine: runs a loaded recipe's steps, in order, on one part, and turns the
// measured values into checks and a verdict. facetd and `facet replay` both inspect with it.
//
// A recipe comes prepared from the loader (its images, models and scans loaded once, see
// config/step_kind.hpp); prepareRecipe() adds the station's calibration and finds the unit that
// runs each step. A step that cannot produce its result (part not found, circle not measurable)
// fails the part and every step that uses it; the failure names the step and its cause. Only a
// fault of the inspection itself (an exception, an empty frame) gives Verdict::Error.

#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "algorithms/scan/scan.hpp"
#include "config/recipe.hpp"
#include "config/station_config.hpp"
#include "service/engine/overlay.hpp"
#include "service/engine/part_result.hpp"
#include "service/engine/step_unit.hpp"

namespace facet::service {

// One part as acquired.
struct PartInput {
  cv::Mat image;                   // Mono8, Mono16 or BGR8
  std::optional<scan::Scan> scan;  // live range scan, for scan_align steps
};

struct InspectionOutcome {
  Verdict verdict = Verdict::Error;
  std::vector<Measurement> measurements;
  std::vector<std::string> failedChecks;  // "<step>.<check>" or "<step>: <cause>"
  std::string error;                      // set with Verdict::Error
  std::vector<std::string> notes;         // "<step>: <reservation>" for results that stand
  std::vector<StepTiming> timings;
  double totalMs = 0;
  Overlay overlay;
};

// A recipe ready to inspect parts: immutable, shared by the parts that use it.
struct PreparedRecipe {
  std::shared_ptr<const config::Recipe> loaded;  // as the loader prepared it
  config::Calibration calibration;
  std::vector<const StepUnit*> units;  // the unit that runs each step, in step order
  bool needsImage = false;             // some step measures on the camera image

  [[nodiscard]] const config::Recipe& recipe() const { return *loaded; }
};

// A recipe's steps cannot run here (a kind without a unit) or the calibration is unusable.
struct InspectionSetupError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// Throws InspectionSetupError naming the recipe file and the cause.
std::shared_ptr<const PreparedRecipe> prepareRecipe(std::shared_ptr<const config::Recipe> recipe,
                                                    const config::Calibration& calibration);

// Never throws: faults become Verdict::Error with the cause. Safe to call from several threads.
[[nodiscard]] InspectionOutcome inspectPart(const PartInput& part, const PreparedRecipe& recipe);

// Copies an inspection's verdict, measurements, failed checks, error, notes and timings into the
// part (facetd's store and the replay report keep the same record of a part).
void recordOutcome(PartResult& part, const InspectionOutcome& outcome);

}  // namespace facet::service
