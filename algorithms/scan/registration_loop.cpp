#include "algorithms/scan/registration_loop.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <optional>
#include <vector>

#include "algorithms/scan/pose_solver.hpp"

namespace facet::scan {
namespace {

// CP rule, scan -> reference: each scan point with its closest reference point.
void addForwardPairs(const ScanSurface& reference, const ScanSurface& scan, const ScanPose& pose,
                     double gate2, std::vector<PointPair>& pairs) {
  for (std::size_t i = 0; i < scan.size(); ++i) {
    const Eigen::Vector2d& a = scan.points()[i];
    const auto [j, d2] = reference.closest(pose.apply(a));
    if (d2 > gate2) continue;
    pairs.push_back({a, reference.points()[j], reference.normal(j), d2});
  }
}

// CP rule, reference -> scan: each reference point with its closest scan point. The query goes
// through the inverse pose so the scan's k-d tree is built once, not per iteration.
void addBackwardPairs(const ScanSurface& reference, const ScanSurface& scan, const ScanPose& pose,
                      double gate2, std::vector<PointPair>& pairs) {
  const ScanPose inverse = pose.inverse();
  for (std::size_t j = 0; j < reference.size(); ++j) {
    const Eigen::Vector2d& b = reference.points()[j];
    const auto [i, d2] = scan.closest(inverse.apply(b));
    if (d2 > gate2) continue;
    pairs.push_back({scan.points()[i], b, pose.rotate(scan.normal(i)), d2});
  }
}

// The squared error per residual row that a pair adds to the metric being minimised, at `pose`:
// one row along the normal (point-to-line), two rows x and y otherwise, so that pairs with and
// without a normal are ranked on one scale.
double metricError(const PointPair& p, const ScanPose& pose, bool pointToLine) {
  const Eigen::Vector2d e = pose.apply(p.a) - p.b;
  return pointToLine && p.normal.squaredNorm() > 0.0 ? std::pow(p.normal.dot(e), 2)
                                                     : e.squaredNorm() / 2.0;
}

// Drops the pairs that do not fit: those whose error under the metric being minimised lies
// beyond 3 robust standard deviations (1.4826 x the median absolute error), the worst first, at
// most 1 - `fraction` of them (trimmed ICP). A pair on what only one scan sees is far off and
// goes; on a clean pair (Gaussian noise) almost none does. Dropping a fixed share instead made
// the kept set depend on the path the pose took, and ranking by the point-to-point distance
// while fitting point-to-line dropped pairs for their offset along the surface, which the fit
// cannot see: DCP and IDCP BoC then stopped up to 0.4 mm apart on a clean corner (scan_000).
void trim(std::vector<PointPair>& pairs, double fraction, int minimum, const ScanPose& pose,
          bool pointToLine) {
  if (fraction >= 1.0 || pairs.empty()) return;
  const auto keep = std::max<std::size_t>(
      static_cast<std::size_t>(minimum),
      static_cast<std::size_t>(std::ceil(fraction * static_cast<double>(pairs.size()))));
  if (keep >= pairs.size()) return;
  std::vector<std::pair<double, std::size_t>> ranked(pairs.size());
  for (std::size_t i = 0; i < pairs.size(); ++i)
    ranked[i] = {metricError(pairs[i], pose, pointToLine), i};
  std::sort(ranked.begin(), ranked.end());
  const double medianSquared = ranked[ranked.size() / 2].first;
  const double limit = std::pow(3.0 * 1.4826, 2) * medianSquared;  // (3 sigma)^2
  std::size_t kept = ranked.size();
  while (kept > keep && ranked[kept - 1].first > limit) --kept;
  if (kept == ranked.size()) return;
  std::vector<PointPair> fitting;
  fitting.reserve(kept);
  for (std::size_t k = 0; k < kept; ++k) fitting.push_back(pairs[ranked[k].second]);
  pairs = std::move(fitting);
}

// How far the step from `from` to `to` moves a scan point at most `reach` from the sensor.
double motion(const ScanPose& from, const ScanPose& to, double reach) {
  return std::hypot(to.x - from.x, to.y - from.y) +
         std::abs(std::remainder(to.theta - from.theta, 2.0 * std::numbers::pi)) * reach;
}

double distanceRms(const std::vector<PointPair>& pairs) {
  double sum = 0.0;
  for (const PointPair& p : pairs) sum += p.squaredDistance;
  return std::sqrt(sum / static_cast<double>(pairs.size()));
}

}  // namespace

LoopOutcome runRegistration(const ScanSurface& reference, const ScanSurface& scan,
                            const ScanPose& start, const LoopSettings& settings,
                            const ScanMatchParams& params) {
  LoopOutcome out;
  out.pose = start;
  out.gate = std::max(settings.gate, params.minGate);
  std::vector<PointPair> pairs;
  pairs.reserve(reference.size() + scan.size());
  double previousRms = -1.0;
  bool gateSettled = false;
  std::optional<ScanPose> twoBack;  // the pose before the last step
  double reach = 0.0;               // metres: the scan point farthest from the sensor
  for (const Eigen::Vector2d& p : scan.points()) reach = std::max(reach, p.norm());
  while (out.iterations < settings.maxIterations) {
    ++out.iterations;
    pairs.clear();
    const double gate2 = out.gate * out.gate;
    addForwardPairs(reference, scan, out.pose, gate2, pairs);
    if (settings.dual) addBackwardPairs(reference, scan, out.pose, gate2, pairs);
    trim(pairs, params.trimFraction, params.minCorrespondences, out.pose, settings.pointToLine);
    out.correspondences = static_cast<int>(pairs.size());
    if (out.correspondences < params.minCorrespondences) {
      out.status.cause = MatchCause::TooFewCorrespondences;
      return out;
    }
    out.rms = pairRms(pairs, out.pose, settings.pointToLine);
    if (settings.residualTolerance > 0.0 && gateSettled && previousRms >= 0.0 &&
        std::abs(previousRms - out.rms) < settings.residualTolerance) {
      out.status.cause = MatchCause::ResidualSettled;
      return out;
    }
    previousRms = out.rms;

    const ScanPose next =
        settings.pointToLine ? stepPointToLine(pairs, out.pose) : solvePointToPoint(pairs);
    const double moved = motion(out.pose, next, reach);
    const double back = twoBack ? motion(*twoBack, next, reach) : moved;
    twoBack = out.pose;
    out.pose = next;

    // The gate follows the residual down (never up), so far-off pairs stop pulling once the
    // scans are close; while it still shrinks the pose is not settled.
    const double gate =
        std::clamp(params.gateFactor * distanceRms(pairs), params.minGate, out.gate);
    gateSettled = gate >= out.gate * 0.999;
    out.gate = gate;
    if (gateSettled && std::min(moved, back) < params.poseTolerance) {
      out.status.cause = MatchCause::PoseSettled;  // converged
      out.rms = pairRms(pairs, out.pose, settings.pointToLine);
      return out;
    }
  }
  out.status.cause = MatchCause::MaxIterations;
  return out;
}

}  // namespace facet::scan
