#pragma once
// The outcome of one part: what the inspection measured, the verdict, and where it came from.
// Produced by the inspection, consumed by every publisher (PLC, results store, archive, HTTP).

#include <chrono>
#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace facet::service {

enum class Verdict {
  Pass,
  Fail,
  // The part was not inspected, or not completely (lost frame, incomplete frame, recipe error,
  // algorithm failure). Never reported as good.
  Error,
};

const char* verdictName(Verdict v);
// The verdict a stored name stands for; anything but "pass" and "fail" is Error (never good).
Verdict verdictFromName(std::string_view name);

// One checked (or merely reported) value of a recipe step.
struct Measurement {
  std::string name;  // "<step>.<value>", e.g. "bore.diameter"
  double value = 0;
  std::string unit;  // mm, deg, px, score
  std::optional<double> nominal;
  std::optional<double> tolMinus;
  std::optional<double> tolPlus;
  bool checked = false;  // has a tolerance band
  bool pass = true;      // inside the band (true when not checked)
};

struct StepTiming {
  std::string step;
  double ms = 0;
};

struct PartResult {
  std::uint64_t partId = 0;  // the daemon's own counter, unique per run of the results store
  std::chrono::system_clock::time_point time;
  int recipeId = 0;
  std::string recipeName;
  std::string recipeVersion;  // content hash of the recipe file
  std::uint64_t frameId = 0;
  std::string source;           // image file or camera
  std::string serial;           // from the sidecar, when there is one
  std::string expectedVerdict;  // from the sidecar, when there is one (replay regression)
  std::string recordedDefect;   // the sidecar's `defect`: what was wrong with a recorded part
  Verdict verdict = Verdict::Error;
  std::vector<std::string> failedChecks;  // measurement names (or step names) that failed
  std::string error;                      // why the verdict is Error
  // "<step>: <reservation>" of results that stand with one ("part of the caliper lies outside
  // the image: measured inside only"), so that a reviewer sees them without the picture.
  std::vector<std::string> notes;
  std::vector<Measurement> measurements;
  std::vector<StepTiming> timings;
  double inspectionMs = 0;
};

}  // namespace facet::service
