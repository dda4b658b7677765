#pragma once
// Solving for the scan pose from point pairs (internal to facet_scan).

#include <span>

#include <Eigen/Core>

#include "algorithms/scan/scan_pose.hpp"

namespace facet::scan {

// One correspondence: scan point `a` (scan frame) belongs with reference point `b` (reference
// frame). `normal` is the unit normal of the line the pair lies on, in the reference frame, or
// zero when there is none (then the point-to-line error falls back to point-to-point).
struct PointPair {
  Eigen::Vector2d a;
  Eigen::Vector2d b;
  Eigen::Vector2d normal;
  double squaredDistance = 0.0;  // |pose(a) - b|^2 at the pose the pair was found with
};

// The pose minimising sum |R a + t - b|^2, in closed form (2D Kabsch / Horn).
[[nodiscard]] ScanPose solvePointToPoint(std::span<const PointPair> pairs);

// One Gauss-Newton step from `current` on sum (n . (R a + t - b))^2 (point-to-point rows for
// pairs without a normal). A tiny damping keeps corridor-like (degenerate) cases finite.
[[nodiscard]] ScanPose stepPointToLine(std::span<const PointPair> pairs, const ScanPose& current);

// RMS of the point-to-point or point-to-line error of the pairs at `pose`, metres.
[[nodiscard]] double pairRms(std::span<const PointPair> pairs, const ScanPose& pose,
                             bool pointToLine);

}  // namespace facet::scan
