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

// RANSAC on minimal samples (2 / 3 / 4 pairs), then least squares on the inliers, twice.
std::optional<TransformFit> fitTransformRobust(const std::vector<cv::Point2d>& src,
                                               const std::vector<cv::Point2d>& dst,
                                               const TransformFitParams& params);

// Hypotheses from single matches: match k's local linear map L_k (ref offsets -> image offsets,
// from its regions' shapes and the NCC's rotation/scale shift) predicts q = dst_k + L_k (p -
// src_k) near it. The matches each hypothesis explains (tolerance growing with the distance
// from src_k) form a consensus set with a high inlier ratio, on which fitTransformRobust runs.
// This finds the transform when outliers are too many for minimal-sample RANSAC. The best of
// these fits and of plain fitTransformRobust (most inliers) is returned.
std::optional<TransformFit> fitTransformWithLocalMaps(const std::vector<cv::Point2d>& src,
                                                      const std::vector<cv::Point2d>& dst,
                                                      const std::vector<cv::Matx22d>& localMaps,
                                                      const TransformFitParams& params);

// |H src - dst| (pixels); infinity when src maps to infinity.
double transferError(const cv::Matx33d& H, cv::Point2d src, cv::Point2d dst);

}  // namespace facet
