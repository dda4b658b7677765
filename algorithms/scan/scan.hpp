#pragma once
// A 2D range scan: the points a laser scanner (or a line profiler) saw, in metres, in the
// sensor's own frame (x forward, y left, right-handed), kept in beam order. Beam order matters:
// segmentation into clusters walks neighbouring beams.

#include <span>
#include <vector>

#include <Eigen/Core>

namespace facet::scan {

struct Scan {
  std::vector<Eigen::Vector2d> points;  // metres, sensor frame, in beam order

  [[nodiscard]] bool empty() const { return points.empty(); }
  [[nodiscard]] std::size_t size() const { return points.size(); }
};

// Which beams count as returns when a scan is built from ranges.
struct RangeLimits {
  double minRange = 0.0;  // metres; ranges <= minRange are dropped (no echo / blinded)
  double maxRange =
      80.0;  // metres; ranges >= maxRange are dropped (CARMEN writes ~81.9 for "none")
};

// Builds a scan from ranges of evenly spread beams: beam i points at firstAngle + i * angleStep
// (radians, counter-clockwise from x). NaN, inf and out-of-limit ranges are dropped.
[[nodiscard]] Scan scanFromRanges(std::span<const double> ranges, double firstAngle,
                                  double angleStep, const RangeLimits& limits = {});

// Builds a scan from (angle, range) beams; angles in radians. Bad ranges are dropped as above.
[[nodiscard]] Scan scanFromPolar(std::span<const double> angles, std::span<const double> ranges,
                                 const RangeLimits& limits = {});

}  // namespace facet::scan
