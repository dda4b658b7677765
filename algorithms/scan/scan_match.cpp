#include "algorithms/scan/scan_match.hpp"

#include <algorithm>

#include "algorithms/scan/registration_loop.hpp"
#include "algorithms/scan/scan_surface.hpp"

namespace facet::scan {
namespace {

constexpr int kFullHalfWindow = 2;     // local line from 5 neighbouring beams
constexpr int kReducedHalfWindow = 1;  // reduced points are already ~spacing apart

ScanSurface fullSurface(const Scan& scan, const ScanMatchParams& params) {
  return ScanSurface({scan, segmentScan(scan, params.segmentation)}, kFullHalfWindow);
}

ScanMatchResult toResult(const LoopOutcome& outcome, int iterations) {
  return {outcome.pose, iterations, outcome.rms, outcome.correspondences, outcome.status};
}

// IDCP BoC: DCP on the cluster-reduced scans until the residual settles (fast, and the reduced
// data smooth the error surface), then DCP on the full scans for accuracy.
ScanMatchResult matchIdcpBoc(const Scan& reference, const Scan& scan, const ScanPose& initial,
                             const ScanMatchParams& params) {
  const bool pointToLine = params.dualMetric == ScanMetric::PointToLine;
  const auto reduce = [&](const Scan& s) {
    return reduceClusters(s, segmentScan(s, params.segmentation), params.reductionSpacing);
  };
  const ScanSurface reducedReference(reduce(reference), kReducedHalfWindow);
  const ScanSurface reducedScan(reduce(scan), kReducedHalfWindow);

  ScanPose start = initial;
  double gate = params.initialGate;
  int used = 0;
  const auto minimum = static_cast<std::size_t>(params.minCorrespondences);
  if (reducedReference.size() >= minimum && reducedScan.size() >= minimum) {
    const LoopOutcome coarse = runRegistration(reducedReference, reducedScan, initial,
                                               {true, pointToLine, params.reducedResidualTolerance,
                                                params.maxIterations, params.initialGate},
                                               params);
    used = coarse.iterations;
    if (coarse.status.cause != MatchCause::TooFewCorrespondences) {
      start = coarse.pose;
      gate = coarse.gate;
    }
  }
  const LoopOutcome fine = runRegistration(
      fullSurface(reference, params), fullSurface(scan, params), start,
      {true, pointToLine, 0.0, std::max(1, params.maxIterations - used), gate}, params);
  return toResult(fine, used + fine.iterations);
}

}  // namespace

std::string_view toString(MatchCause cause) {
  switch (cause) {
    case MatchCause::PoseSettled:
      return "pose_settled";
    case MatchCause::ResidualSettled:
      return "residual_settled";
    case MatchCause::MaxIterations:
      return "max_iterations";
    case MatchCause::TooFewCorrespondences:
      return "too_few_correspondences";
    case MatchCause::EmptyScan:
      return "empty_scan";
  }
  return "unknown";
}

std::string_view toString(ScanMatchMethod method) {
  switch (method) {
    case ScanMatchMethod::IcpPointToPoint:
      return "icp";
    case ScanMatchMethod::IcpPointToLine:
      return "icp-line";
    case ScanMatchMethod::Dcp:
      return "dcp";
    case ScanMatchMethod::IdcpBoc:
      return "idcp";
  }
  return "unknown";
}

ScanMatchResult matchScans(const Scan& reference, const Scan& scan, const ScanPose& initial,
                           const ScanMatchParams& params) {
  const auto minimum = static_cast<std::size_t>(std::max(1, params.minCorrespondences));
  if (reference.size() < minimum || scan.size() < minimum) {
    ScanMatchResult empty;
    empty.pose = initial;
    empty.status.cause = MatchCause::EmptyScan;
    return empty;
  }
  if (params.method == ScanMatchMethod::IdcpBoc)
    return matchIdcpBoc(reference, scan, initial, params);

  const bool dual = params.method == ScanMatchMethod::Dcp;
  const bool pointToLine = params.method == ScanMatchMethod::IcpPointToLine ||
                           (dual && params.dualMetric == ScanMetric::PointToLine);
  const LoopOutcome outcome =
      runRegistration(fullSurface(reference, params), fullSurface(scan, params), initial,
                      {dual, pointToLine, 0.0, params.maxIterations, params.initialGate}, params);
  return toResult(outcome, outcome.iterations);
}

}  // namespace facet::scan
