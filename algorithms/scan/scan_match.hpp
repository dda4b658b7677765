#pragma once
// Registration of one 2D range scan against a reference scan.
//
// Four methods share one iteration (find correspondences, gate, trim, solve for the pose):
//   IcpPointToPoint  ICP, closest-point (CP) rule: scan -> reference pairs, point-to-point error.
//   IcpPointToLine   ICP, CP rule, point-to-line error (distance to the reference's local line).
//   Dcp              dual closest point rule: CP pairs found both ways (scan -> reference and
//                    reference -> scan) and used together; avoids the wrong minima that ICP
//                    falls into when parts of either scan are occluded in the other.
//   IdcpBoc          iterative DCP based on clusters: both scans are cut into clusters
//                    (adaptive breakpoints), each cluster reduced to fewer points; DCP runs on
//                    the reduced data until the residual settles, then on the full data.
// (Xu, Zhang, Xu, Robot 2010, 32(3):352-357; seed dissertation, part 4.)
//
// Both-way pairs are gated: a pair is used only while its points are closer than the current
// gate, which shrinks with the residual. Pooling them without a gate halves the success rate
// on large displacements.

#include <string_view>

#include "algorithms/scan/scan.hpp"
#include "algorithms/scan/scan_pose.hpp"
#include "algorithms/scan/scan_segmentation.hpp"
#include "algorithms/status/status.hpp"

namespace facet::scan {

enum class ScanMatchMethod { IcpPointToPoint, IcpPointToLine, Dcp, IdcpBoc };

// The error DCP / IDCP BoC minimise (ICP's is fixed by its method).
enum class ScanMetric { PointToPoint, PointToLine };

struct ScanMatchParams {
  ScanMatchMethod method = ScanMatchMethod::IdcpBoc;
  ScanMetric dualMetric = ScanMetric::PointToLine;  // error used by Dcp and IdcpBoc

  int maxIterations = 100;  // total over both IDCP phases
  // metres; pairs farther apart are unused in the first iteration. Wide on purpose: the gate
  // then follows the residual down, and a narrow first gate loses large displacements.
  double initialGate = 4.0;
  double minGate = 0.15;  // metres; the gate never shrinks below this
  // next gate = gateFactor * (rms distance of the pairs used), clamped to [minGate, last gate]
  double gateFactor = 3.0;
  // Share of gated pairs kept (the closest ones); 1 = no trimming. Trimming helps the dual rule
  // (pairs on what only one scan sees); on the CARMEN logs plain ICP does better with 1.
  double trimFraction = 0.9;
  int minCorrespondences = 6;  // fewer usable pairs -> not converged, cause TooFewCorrespondences

  // Converged when an iteration moves no point of the scan farther than this (gate settled),
  // or brings the pose back to within this of where it was two iterations before (the
  // trimmed set of pairs alternating). Settling on the residual instead stopped too early: at
  // the minimum the rms hardly changes while the pose still drifts along a weakly held direction
  // (on a corner far from the sensor, y against the angle), and DCP and IDCP BoC ended up to
  // 0.4 mm apart on the same clean pair.
  double poseTolerance = 1e-6;  // metres
  // IDCP BoC leaves the reduced data once its rms changes by less than this.
  double reducedResidualTolerance = 1e-3;  // metres

  SegmentationParams segmentation;  // clusters (normals, IDCP BoC reduction)
  double reductionSpacing = 0.2;    // metres; IDCP BoC keeps about one point per spacing of cluster
};

// Why a match stopped; PoseSettled (0) is the one that counts as converged (Status::ok()).
enum class MatchCause {
  PoseSettled,            // converged: the pose stopped moving (poseTolerance)
  ResidualSettled,        // the reduced phase of IDCP BoC handed over (change of rms below
                          // reducedResidualTolerance); never the cause of a final result
  MaxIterations,          // not converged
  TooFewCorrespondences,  // not converged: fewer than minCorrespondences pairs within the gate
  EmptyScan,              // not converged: a scan had fewer than minCorrespondences points
};

[[nodiscard]] std::string_view toString(MatchCause cause);
[[nodiscard]] std::string_view toString(ScanMatchMethod method);

struct ScanMatchResult {
  ScanPose pose;            // maps the scan into the reference's frame
  int iterations = 0;       // correspondence rounds run (both phases for IDCP BoC)
  double rms = 0.0;         // metres; rms error (point-to-line distance for the line metric) of the
                            // pairs used in the last round
  int correspondences = 0;  // pairs used in the last round (both directions for DCP)
  Status<MatchCause> status{MatchCause::MaxIterations, {}};  // ok(): converged
};

// Aligns `scan` to `reference`, starting from `initial` (scan -> reference). Never throws on
// degenerate data: empty scans give a status with cause EmptyScan (not converged).
[[nodiscard]] ScanMatchResult matchScans(const Scan& reference, const Scan& scan,
                                         const ScanPose& initial = {},
                                         const ScanMatchParams& params = {});

}  // namespace facet::scan
