#pragma once
// Process capability of one measured value over a series of parts: how the spread of the
// process compares with the tolerance band (Cp) and how well it is centred in it (Cpk).
//   Cp  = (upper - lower) / (6 sigma)
//   Cpk = min(upper - mean, mean - lower) / (3 sigma)
// sigma is the sample standard deviation (n - 1). Values that are not finite (a measurement that
// failed) are left out.

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
  std::optional<double> cp;  // set when checked and sigma > 0
  std::optional<double> cpk;
  std::vector<double> values;  // in part order, finite only
};

// One entry per measurement name, in the order names first appear in `parts`.
std::vector<Capability> processCapability(const std::vector<PartResult>& parts);

}  // namespace facet::service
