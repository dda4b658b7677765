#pragma once
// Least-squares refinement of a match (internal to facet_shape): ICP of the model's subpixel
// points against the image's Facet-model subpixel edges, minimising point-to-line distances
// along the image edge normals in position, angle and optionally scale.

#include <opencv2/core.hpp>

#include "algorithms/geometry/pose2d.hpp"
#include "algorithms/shape/find_shape_model.hpp"
#include "algorithms/shape/shape_model.hpp"
#include "algorithms/status/status.hpp"

namespace facet::shape_detail {

// Internal to the search, never reported: no name for logs.
enum class RefinementFailure {
  None,
  TooFewCorrespondences,  // too few model points met image edges; the pose is the start pose
};

struct Refined {
  Pose2D pose;
  double residual = 0.0;  // weighted RMS point-to-line distance, pixels
  Status<RefinementFailure> status;
  // How well the model's points lie on image edges (each weighted by its distance across the
  // edge, 1 on it, 0 from a pixel away) at the refined pose and at the start: a refinement
  // that lowers it has made the pose worse.
  double support = 0.0;
  double startSupport = 0.0;
};

// Refines `pose` using the image's edges inside `roi` (image pixels, clipped to the image).
Refined refineLeastSquares(const cv::Mat& image, const ShapeModel& model, cv::Rect roi, Pose2D pose,
                           Polarity polarity, bool withScale);

}  // namespace facet::shape_detail
