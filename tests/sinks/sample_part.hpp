#pragma once
// A part result as the inspection makes one: a checked diameter, an unchecked score, timings.

#include <string>

#include "service/engine/part_result.hpp"

namespace facet::sinks_test {

inline service::PartResult samplePart(std::uint64_t id) {
  service::PartResult p;
  p.partId = id;
  p.time = std::chrono::system_clock::time_point(
      std::chrono::microseconds(1795986187125331LL + static_cast<long long>(id) * 1000));
  p.recipeId = 3;
  p.recipeName = "flange";
  p.recipeVersion = "9c1e55aa";
  p.frameId = id + 100;
  p.source = "/images/part-" + std::to_string(id) + ".png";
  p.serial = "SN" + std::to_string(id);
  const bool bad = id % 7 == 0;
  p.verdict = bad ? service::Verdict::Fail : service::Verdict::Pass;
  if (bad) p.failedChecks = {"bore.diameter"};
  if (bad) p.recordedDefect = "bore_oversize";  // a recorded part with a known fault
  if (id % 5 == 0) p.notes = {"locate: found off its nominal place"};
  p.measurements.push_back({.name = "bore.diameter",
                            .value = bad ? 12.07 : 12.0 + 0.001 * static_cast<double>(id % 10),
                            .unit = "mm",
                            .nominal = 12.0,
                            .tolMinus = 0.05,
                            .tolPlus = 0.04,
                            .checked = true,
                            .pass = !bad});
  p.measurements.push_back({.name = "locate.score", .value = 0.93, .unit = "score"});
  p.timings = {{"locate", 1.5}, {"bore", 0.75}};
  p.inspectionMs = 2.25;
  return p;
}

}  // namespace facet::sinks_test
