#include "algorithms/scan/scan.hpp"

#include <cmath>

namespace facet::scan {
namespace {

bool isReturn(double range, const RangeLimits& limits) {
  return std::isfinite(range) && range > limits.minRange && range < limits.maxRange;
}

}  // namespace

Scan scanFromRanges(std::span<const double> ranges, double firstAngle, double angleStep,
                    const RangeLimits& limits) {
  Scan scan;
  scan.points.reserve(ranges.size());
  for (std::size_t i = 0; i < ranges.size(); ++i) {
    if (!isReturn(ranges[i], limits)) continue;
    const double a = firstAngle + static_cast<double>(i) * angleStep;
    scan.points.emplace_back(ranges[i] * std::cos(a), ranges[i] * std::sin(a));
  }
  return scan;
}

Scan scanFromPolar(std::span<const double> angles, std::span<const double> ranges,
                   const RangeLimits& limits) {
  Scan scan;
  const std::size_t n = std::min(angles.size(), ranges.size());
  scan.points.reserve(n);
  for (std::size_t i = 0; i < n; ++i) {
    if (!isReturn(ranges[i], limits) || !std::isfinite(angles[i])) continue;
    scan.points.emplace_back(ranges[i] * std::cos(angles[i]), ranges[i] * std::sin(angles[i]));
  }
  return scan;
}

}  // namespace facet::scan
