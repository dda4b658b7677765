#include "algorithms/scan/registration_loop.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
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

// Keeps the closest `fraction` of the pairs (trimmed ICP).
void trim(std::vector<PointPair>& pairs, double fraction, int minimum) {
  if (fraction >= 1.0) return;
  const auto keep = std::max<std::size_t>(
      static_cast<std::size_t>(minimum),
      static_cast<std::size_t>(std::ceil(fraction * static_cast<double>(pairs.size()))));
  if (keep >= pairs.size()) return;
  std::nth_element(
      pairs.begin(), pairs.begin() + static_cast<std::ptrdiff_t>(keep), pairs.end(),
      [](const PointPair& l, const PointPair& r) { return l.squaredDistance < r.squaredDistance; });
  pairs.resize(keep);
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
  while (out.iterations < settings.maxIterations) {
    ++out.iterations;
    pairs.clear();
    const double gate2 = out.gate * out.gate;
    addForwardPairs(reference, scan, out.pose, gate2, pairs);
    if (settings.dual) addBackwardPairs(reference, scan, out.pose, gate2, pairs);
    trim(pairs, params.trimFraction, params.minCorrespondences);
    out.correspondences = static_cast<int>(pairs.size());
    if (out.correspondences < params.minCorrespondences) {
      out.cause = MatchCause::TooFewCorrespondences;
      return out;
    }
    out.rms = pairRms(pairs, out.pose, settings.pointToLine);
    if (gateSettled && previousRms >= 0.0 && std::abs(previousRms - out.rms) < settings.tolerance) {
      out.converged = true;
      out.cause = MatchCause::ResidualSettled;
      return out;
    }
    previousRms = out.rms;

    const ScanPose next =
        settings.pointToLine ? stepPointToLine(pairs, out.pose) : solvePointToPoint(pairs);
    const double moved =
        std::hypot(next.x - out.pose.x, next.y - out.pose.y) +
        std::abs(std::remainder(next.theta - out.pose.theta, 2.0 * std::numbers::pi));
    out.pose = next;

    // The gate follows the residual down (never up), so far-off pairs stop pulling once the
    // scans are close; while it still shrinks the residual is not comparable between rounds.
    const double gate =
        std::clamp(params.gateFactor * distanceRms(pairs), params.minGate, out.gate);
    gateSettled = gate >= out.gate * 0.999;
    out.gate = gate;
    if (moved < 1e-7 && gateSettled) {
      out.converged = true;
      out.cause = MatchCause::PoseSettled;
      out.rms = pairRms(pairs, out.pose, settings.pointToLine);
      return out;
    }
  }
  out.cause = MatchCause::MaxIterations;
  return out;
}

}  // namespace facet::scan
