#pragma once
// Adaptive breakpoint segmentation (Borges & Aldon 2004) of a scan into clusters, and the
// per-cluster reduction used by IDCP BoC.
//
// Two neighbouring beams belong to one cluster unless their points are farther apart than
//     D = r * sin(dphi) / sin(lambda - dphi) + 3 * sigma,
// the gap a surface seen at the grazing angle lambda would leave at range r (dphi: the angle
// between the beams, sigma: range noise). The scan origin is the sensor.

#include <vector>

#include "algorithms/scan/scan.hpp"

namespace facet::scan {

struct SegmentationParams {
  double lambda = 0.17453292519943295;  // radians (10 deg); grazing angle still kept together
  double rangeSigma = 0.02;             // metres; range noise of the sensor
  double minGap = 0.05;                 // metres; neighbours closer than this never split
};

// A run of consecutive points [begin, end) of a scan.
struct Cluster {
  int begin = 0;
  int end = 0;
  [[nodiscard]] int size() const { return end - begin; }
};

[[nodiscard]] std::vector<Cluster> segmentScan(const Scan& scan,
                                               const SegmentationParams& params = {});

// A scan together with its clusters (which cover the scan's points in order).
struct ClusteredScan {
  Scan scan;
  std::vector<Cluster> clusters;
};

// Reduces each cluster to about one point per `spacing` metres of its length: consecutive
// points are averaged in runs no longer than `spacing`. Clusters of one point are dropped
// (isolated returns are mostly noise or moving legs). Keeps beam order; the result's clusters
// are the reduced clusters.
[[nodiscard]] ClusteredScan reduceClusters(const Scan& scan, const std::vector<Cluster>& clusters,
                                           double spacing);

}  // namespace facet::scan
