#include "bench/scan/opencv_icp.hpp"

#include <cmath>
#include <vector>

#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>
#include <opencv2/flann.hpp>

namespace facet::bench {

scan::ScanPose opencvIcp(const scan::Scan& reference, const scan::Scan& scan,
                         const scan::ScanPose& initial, int maxIterations) {
  if (reference.size() < 3 || scan.size() < 3) return initial;
  cv::Mat refPoints(static_cast<int>(reference.size()), 2, CV_32F);
  for (int i = 0; i < refPoints.rows; ++i) {
    refPoints.at<float>(i, 0) = static_cast<float>(reference.points[i].x());
    refPoints.at<float>(i, 1) = static_cast<float>(reference.points[i].y());
  }
  cv::flann::Index tree(refPoints, cv::flann::KDTreeIndexParams(1));
  scan::ScanPose pose = initial;
  cv::Mat query(static_cast<int>(scan.size()), 2, CV_32F), indices, dists;
  std::vector<cv::Point2f> from, to;
  for (int iteration = 0; iteration < maxIterations; ++iteration) {
    for (int i = 0; i < query.rows; ++i) {
      const Eigen::Vector2d q = pose.apply(scan.points[i]);
      query.at<float>(i, 0) = static_cast<float>(q.x());
      query.at<float>(i, 1) = static_cast<float>(q.y());
    }
    tree.knnSearch(query, indices, dists, 1, cv::flann::SearchParams(32));
    from.clear();
    to.clear();
    for (int i = 0; i < query.rows; ++i) {
      const int j = indices.at<int>(i, 0);
      from.emplace_back(query.at<float>(i, 0), query.at<float>(i, 1));
      to.emplace_back(refPoints.at<float>(j, 0), refPoints.at<float>(j, 1));
    }
    const cv::Mat step =
        cv::estimateAffinePartial2D(from, to, cv::noArray(), cv::RANSAC, 0.3, 200, 0.99, 10);
    if (step.empty()) break;
    // The step maps already-moved points: compose it (without its scale) onto the pose.
    const double a = step.at<double>(0, 0), b = step.at<double>(1, 0);
    const scan::ScanPose delta{step.at<double>(0, 2), step.at<double>(1, 2), std::atan2(b, a)};
    pose = delta * pose;
    if (std::hypot(delta.x, delta.y) < 1e-5 && std::abs(delta.theta) < 1e-6) break;
  }
  return pose;
}

}  // namespace facet::bench
