#include "service/engine/inspect_part.hpp"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <map>

#include "algorithms/image/grey_image.hpp"

namespace facet::service {
namespace {

using Clock = std::chrono::steady_clock;

double toCheckUnit(double value, const config::Check& check, bool lengthsInMm, double mmPerPixel) {
  if (check.quantity != config::Quantity::Length && check.quantity != config::Quantity::Area)
    return value;
  // An area scales with the square of a length.
  const double factor =
      check.quantity == config::Quantity::Area ? mmPerPixel * mmPerPixel : mmPerPixel;
  if (lengthsInMm) return check.unit == config::Unit::Pixel ? value / factor : value;
  return check.unit == config::Unit::Millimetre ? value * factor : value;
}

std::string unitName(const config::Check& check) {
  switch (check.quantity) {
    case config::Quantity::Count:
      return "count";
    case config::Quantity::Score:
      return "score";
    case config::Quantity::Area:
      return std::string(config::toString(check.unit)) + "2";
    default:
      return std::string(config::toString(check.unit));
  }
}

// Every checked value of a step is reported, failed steps included (as NaN), so that a row in
// the results store always has the recipe's full set of values.
Measurement checked(const config::Step& step, const config::Check& check, const StepResult& result,
                    double mmPerPixel) {
  Measurement m;
  m.name = step.id + "." + check.name;
  m.unit = unitName(check);
  m.nominal = check.nominal;
  m.tolMinus = check.tolMinus;
  m.tolPlus = check.tolPlus;
  m.checked = true;
  const auto it = result.values.find(check.name);
  if (result.ok && it != result.values.end()) {
    m.value = toCheckUnit(it->second, check, result.lengthsInMm, mmPerPixel);
    m.pass = check.passes(m.value);
  } else {
    m.value = std::nan("");
    m.pass = false;
  }
  return m;
}

// "<step> diameter=6.012 x=0.003": the step's values beside its position on the image.
std::string labelText(const std::string& stepId, const std::vector<Measurement>& values) {
  std::string text = stepId;
  for (const auto& m : values) {
    if (!std::isfinite(m.value)) continue;
    char buf[64];
    std::snprintf(buf, sizeof buf, " %s=%.3f", m.name.substr(stepId.size() + 1).c_str(), m.value);
    text += buf;
  }
  return text;
}

}  // namespace

std::shared_ptr<const PreparedRecipe> prepareRecipe(std::shared_ptr<const config::Recipe> recipe,
                                                    const config::Calibration& calibration) {
  if (!recipe) throw InspectionSetupError("no recipe");
  if (!(calibration.mmPerPixel > 0))
    throw InspectionSetupError("calibration: mm per pixel must be > 0");
  auto prepared = std::make_shared<PreparedRecipe>();
  for (const config::Step& step : recipe->steps) {
    const auto* unit = dynamic_cast<const StepUnit*>(step.kind);
    if (unit == nullptr)
      throw InspectionSetupError(recipe->file.string() + ": step '" + step.id + "' of kind '" +
                                 std::string(step.kindName()) + "' cannot run: no step unit");
    prepared->units.push_back(unit);
    prepared->needsImage = prepared->needsImage || unit->needsImage();
  }
  prepared->loaded = std::move(recipe);
  prepared->calibration = calibration;
  return prepared;
}

InspectionOutcome inspectPart(const PartInput& part, const PreparedRecipe& prepared) {
  InspectionOutcome out;
  const auto start = Clock::now();
  try {
    if (prepared.needsImage && part.image.empty()) throw std::invalid_argument("empty image");
    const cv::Mat grey = part.image.empty() ? cv::Mat() : toGrey(part.image);
    std::map<std::string, StepResult> done;
    StepContext context{grey, part.scan, prepared.calibration, done, out.overlay};
    const double mmPerPixel = prepared.calibration.mmPerPixel;
    bool allPass = true;
    const auto& steps = prepared.recipe().steps;
    for (std::size_t i = 0; i < steps.size(); ++i) {
      const config::Step& step = steps[i];
      const auto t0 = Clock::now();
      std::string blockedBy;
      for (const auto& input : step.inputs)
        if (!done.at(input).ok) blockedBy = input;
      StepResult result = blockedBy.empty()
                              ? prepared.units[i]->run(step, context)
                              : StepResult::failed("depends on failed step '" + blockedBy + "'");
      out.timings.push_back(
          {step.id, std::chrono::duration<double, std::milli>(Clock::now() - t0).count()});
      if (!result.ok) {
        allPass = false;
        out.failedChecks.push_back(step.id + ": " + result.cause);
      }
      std::vector<Measurement> values;
      bool stepPass = result.ok;
      for (const config::Check& check : step.checks) {
        Measurement m = checked(step, check, result, mmPerPixel);
        if (!m.pass) {
          allPass = stepPass = false;
          if (result.ok) out.failedChecks.push_back(m.name);
        }
        values.push_back(std::move(m));
      }
      if (result.point)
        out.overlay.label(
            *result.point + cv::Point2d(8, -8),
            labelText(step.id, values) + (result.note.empty() ? "" : " (" + result.note + ")"),
            stepPass);
      if (!result.note.empty()) out.notes.push_back(step.id + ": " + result.note);
      out.measurements.insert(out.measurements.end(), values.begin(), values.end());
      done.emplace(step.id, std::move(result));
    }
    out.verdict = allPass ? Verdict::Pass : Verdict::Fail;
  } catch (const std::exception& e) {
    out.verdict = Verdict::Error;
    out.error = std::string("inspection fault: ") + e.what();
  }
  out.totalMs = std::chrono::duration<double, std::milli>(Clock::now() - start).count();
  return out;
}

void recordOutcome(PartResult& part, const InspectionOutcome& outcome) {
  part.verdict = outcome.verdict;
  part.measurements = outcome.measurements;
  part.failedChecks = outcome.failedChecks;
  part.error = outcome.error;
  part.notes = outcome.notes;
  part.timings = outcome.timings;
  part.inspectionMs = outcome.totalMs;
}

}  // namespace facet::service
