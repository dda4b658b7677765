#pragma once
// Process capability of one measured value over a series of parts: how the spread of the
// process compares with the tolerance band (Cp) and how well it is centred in it (Cpk).
//   Cp  = (upper - lower) / (6 sigma)
//   Cpk = min(upper - mean, mean - lower) / (3 sigma)
// sigma is the sample standard deviation (n - 1). Values that are not finite (a measurement that
// failed) are left out.
//
// A limit at the quantity's natural bound is no limit of the process: a position error or a
// roundness cannot fall below 0, so a band [0, 0.1] is one-sided, and measuring the mean's
// distance to 0 would call a good process (values near 0) "not capable". There the one-sided
// index of the real limit is used, as ISO 22514-4 does: Cpu = (upper - mean) / (3 sigma), or
// Cpl = (mean - lower) / (3 sigma) at a natural upper bound (a score of 1); no Cp.

#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "service/engine/part_result.hpp"

namespace facet::service {

struct Capability {
  std::string name;  // "<step>.<value>"
  std::string unit;
  std::size_t count = 0;  // finite values used
  double mean = 0;
  double sigma = 0;             // 0 with fewer than two values
  std::optional<double> lower;  // tolerance limits, when the value is checked
  std::optional<double> upper;
  std::optional<double> nominal;
  std::optional<double> cp;    // set when both limits are real and sigma > 0
  std::optional<double> cpk;   // the capability index named by `index`
  std::string index;           // "Cpk" (two limits), "Cpu" or "Cpl" (one limit is a natural bound)
  std::vector<double> values;  // in part order, finite only
};

// The natural bounds of a measured value, by its name "<step>.<value>": the recipe format's
// minimum of that check (distances, diameters, roundness, counts: 0) and 1 for scores.
struct NaturalBounds {
  std::optional<double> lower;
  std::optional<double> upper;
};
NaturalBounds naturalBounds(const std::string& name, const std::string& unit);

// One entry per measurement name, in the order names first appear in `parts`.
std::vector<Capability> processCapability(const std::vector<PartResult>& parts);

}  // namespace facet::service
