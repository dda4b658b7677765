#pragma once
// A blob measured in the measuring plane, in mm: its area, centroid and ellipse as integrals over
// the plane of the share of each pixel the blob covers (BlobCoverage).
//
// Why not the image centroid mapped and the area times the scale there: under perspective the
// plane's scale changes across a blob, and the image centroid is not the image of the blob's
// centroid in the plane. Through a pinhole of 2300 px focal length, a disc of radius 10 mm on a
// plane tilted 25 degrees 300 mm away has its mapped image centroid 0.14 mm from its centre (a
// 25 mm disc at 40 degrees: 1.3 mm; bench_plane_measures: 0.013-0.072 mm for 6 mm discs), the
// same bias that moves the image of a circle's centre off the centre of its
// ellipse. Each pixel instead counts at its own place in the plane with its own area there.

#include <optional>

#include <opencv2/core.hpp>

#include "algorithms/calibration/world_mapping.hpp"
#include "algorithms/measure/blob_analysis.hpp"

namespace facet {

struct PlaneBlob {
  cv::Point2d centreMm;
  double areaMm2 = 0;
  // The equal-moment ellipse in the plane, scaled to the area (as Blob's), mm; its major axis
  // in degrees counter-clockwise from the plane's x axis as seen on screen (the plane's y runs
  // down the image as pixels do), (-90, 90].
  double majorRadiusMm = 0, minorRadiusMm = 0, angleDeg = 0;
};

// nullopt when the blob has no coverage (analysed without BlobParams::keepCoverage) or part of
// it does not map into the plane.
std::optional<PlaneBlob> blobInPlane(const Blob& blob, const WorldMapping& plane);

}  // namespace facet
