#include "algorithms/scan/scan_segmentation.hpp"

#include <algorithm>
#include <cmath>

namespace facet::scan {
namespace {

// Angle between the beams of two neighbouring points seen from the sensor at the origin.
double beamAngle(const Eigen::Vector2d& a, const Eigen::Vector2d& b) {
  const double cross = a.x() * b.y() - a.y() * b.x();
  return std::abs(std::atan2(cross, a.dot(b)));
}

// The largest gap between neighbours that still belongs to one surface (adaptive breakpoint).
double breakDistance(const Eigen::Vector2d& previous, const Eigen::Vector2d& current,
                     const SegmentationParams& params) {
  const double dphi = beamAngle(previous, current);
  const double r = previous.norm();
  // A beam gap wider than the grazing angle means no surface joins them.
  if (dphi >= params.lambda) return params.minGap;
  const double d = r * std::sin(dphi) / std::sin(params.lambda - dphi) + 3.0 * params.rangeSigma;
  return std::max(d, params.minGap);
}

}  // namespace

std::vector<Cluster> segmentScan(const Scan& scan, const SegmentationParams& params) {
  std::vector<Cluster> clusters;
  const int n = static_cast<int>(scan.size());
  if (n == 0) return clusters;
  int begin = 0;
  for (int i = 1; i < n; ++i) {
    const auto& p = scan.points[i - 1];
    const auto& q = scan.points[i];
    if ((q - p).norm() > breakDistance(p, q, params)) {
      clusters.push_back({begin, i});
      begin = i;
    }
  }
  clusters.push_back({begin, n});
  return clusters;
}

ClusteredScan reduceClusters(const Scan& scan, const std::vector<Cluster>& clusters,
                             double spacing) {
  ClusteredScan reduced;
  reduced.scan.points.reserve(scan.size());
  for (const Cluster& cluster : clusters) {
    if (cluster.size() < 2) continue;
    const int first = static_cast<int>(reduced.scan.size());
    int runBegin = cluster.begin;
    // Average runs of consecutive points whose extent stays within `spacing`.
    for (int i = cluster.begin; i <= cluster.end; ++i) {
      const bool runEnds =
          i == cluster.end || (scan.points[i] - scan.points[runBegin]).norm() > spacing;
      if (!runEnds) continue;
      Eigen::Vector2d sum = Eigen::Vector2d::Zero();
      for (int j = runBegin; j < i; ++j) sum += scan.points[j];
      reduced.scan.points.push_back(sum / static_cast<double>(i - runBegin));
      runBegin = i;
    }
    reduced.clusters.push_back({first, static_cast<int>(reduced.scan.size())});
  }
  return reduced;
}

}  // namespace facet::scan
