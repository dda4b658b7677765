#pragma once
// Robust fit of a plane transform to point correspondences: RANSAC on minimal samples
// (algorithms/geometry/ransac.hpp), then least squares on the inliers (normalised DLT for the
// homography), repeated once with the refitted model's inliers.

#include <optional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

namespace facet {

enum class TransformModel { Similarity, Affine, Homography };

// "similarity" | "affine" | "homography"; returns false on an unknown name.
bool parseTransformModel(const std::string& name, TransformModel& model);

struct TransformFitParams {
  TransformModel model = TransformModel::Homography;
  double inlierThreshold = 3.0;  // pixels, reprojection error in the target
  int maxIterations = 4000;
  double confidence = 0.999;
};

struct TransformFit {
  cv::Matx33d H = cv::Matx33d::eye();  // source -> target, H(2,2) == 1
  std::vector<int> inliers;
};

// Least-squares transform from all given pairs (no outlier rejection); nullopt if degenerate.
std::optional<cv::Matx33d> fitTransformLeastSquares(const std::vector<cv::Point2d>& src,
                                                    const std::vector<cv::Point2d>& dst,
                                                    TransformModel model);

std::optional<TransformFit> fitTransformRobust(const std::vector<cv::Point2d>& src,
                                               const std::vector<cv::Point2d>& dst,
                                               const TransformFitParams& params);

}  // namespace facet
