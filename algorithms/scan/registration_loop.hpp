#pragma once
// The iteration every method shares (internal to facet_scan): find closest-point pairs (one
// way for ICP's CP rule, both ways for the DCP rule), gate, trim, solve, until the residual
// settles.

#include "algorithms/scan/scan_match.hpp"
#include "algorithms/scan/scan_surface.hpp"

namespace facet::scan {

struct LoopSettings {
  bool dual = false;         // DCP rule (both ways) instead of the CP rule
  bool pointToLine = false;  // error metric
  // metres; > 0: also stop when the rms changes less (with the gate settled): the hand-over of
  // a coarse phase, never a final result (ScanMatchParams::poseTolerance)
  double residualTolerance = 0.0;
  int maxIterations = 100;
  double gate = 1.5;  // metres; gate of the first iteration
};

struct LoopOutcome {
  ScanPose pose;
  int iterations = 0;
  double rms = 0.0;
  int correspondences = 0;
  double gate = 0.0;  // the gate reached, to start a following phase with
  // ok(): converged (PoseSettled); ResidualSettled is a hand-over, not converged
  Status<MatchCause> status{MatchCause::MaxIterations, {}};
};

[[nodiscard]] LoopOutcome runRegistration(const ScanSurface& reference, const ScanSurface& scan,
                                          const ScanPose& start, const LoopSettings& settings,
                                          const ScanMatchParams& params);

}  // namespace facet::scan
