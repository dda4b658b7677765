#pragma once
// The in-run baseline: a plain ICP built from OpenCV parts only. Nearest neighbours from
// cv::flann (k-d tree), the pose from cv::estimateAffinePartial2D (RANSAC, then refined) on
// the pairs, iterated until the pose stops moving. There is no PCL on this machine; the issue
// quotes PCL's figures for reference.

#include "algorithms/scan/scan.hpp"
#include "algorithms/scan/scan_pose.hpp"

namespace facet::bench {

[[nodiscard]] scan::ScanPose opencvIcp(const scan::Scan& reference, const scan::Scan& scan,
                                       const scan::ScanPose& initial, int maxIterations = 30);

}  // namespace facet::bench
