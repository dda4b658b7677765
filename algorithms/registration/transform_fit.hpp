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

// The distinct consensus sets of a small match set, most inliers first (fewest squared errors on
// a tie), at most `count`: every minimal sample whose points keep their orientation (the
// triangles they span turn the same way in both images, as under any transform that does not
// fold the plane) is fitted, and each inlier set found is polished by least squares. Where true
// matches are a few among many (a 60 degree viewpoint change: 6 of 40), a random sample is all
// true too seldom for RANSAC to draw one, and their set may tie with a chance one: the caller
// verifies the candidates in turn. Empty when there are more than 64 matches or more than
// `maxSamples` minimal samples.
std::vector<TransformFit> enumerateConsensusSets(const std::vector<cv::Point2d>& src,
                                                 const std::vector<cv::Point2d>& dst,
                                                 const TransformFitParams& params, int count,
                                                 long maxSamples);

// |H src - dst| (pixels); infinity when src maps to infinity.
double transferError(const cv::Matx33d& H, cv::Point2d src, cv::Point2d dst);

}  // namespace facet
