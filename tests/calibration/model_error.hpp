#pragma once
// How far an estimated camera is from the true one where it matters: the RMS pixel distance,
// over the covered part of the field, between a pixel and where the estimated camera puts the
// true camera's ray through that pixel, after the best rotation between the two cameras (a
// calibration cannot tell a small rotation of the camera from one of every plate pose).

#include <algorithm>
#include <cmath>
#include <vector>

#include <Eigen/Dense>
#include <opencv2/core.hpp>

#include "algorithms/calibration/camera_model.hpp"

namespace facet::test {

inline double modelError(const CameraModel& est, const CameraModel& truth, const cv::Mat& covered) {
  std::vector<Eigen::Vector3d> a, b;
  std::vector<cv::Point2d> pixels;
  for (int y = 8; y < covered.rows; y += 16)
    for (int x = 8; x < covered.cols; x += 16) {
      if (!covered.at<uchar>(y, x)) continue;
      const cv::Point2d p(x, y);
      const cv::Point2d nt = truth.undistort(p), ne = est.undistort(p);
      a.push_back(Eigen::Vector3d(nt.x, nt.y, 1).normalized());
      b.push_back(Eigen::Vector3d(ne.x, ne.y, 1).normalized());
      pixels.push_back(p);
    }
  if (a.empty()) return 0;
  Eigen::Matrix3d H = Eigen::Matrix3d::Zero();
  for (std::size_t i = 0; i < a.size(); ++i) H += a[i] * b[i].transpose();
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(H, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d V = svd.matrixV();
  if ((V * svd.matrixU().transpose()).determinant() < 0) V.col(2) *= -1;
  const Eigen::Matrix3d R = V * svd.matrixU().transpose();
  double sum = 0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    const Eigen::Vector3d r = R * a[i];
    sum += std::pow(cv::norm(est.project({r.x(), r.y(), r.z()}) - pixels[i]), 2);
  }
  return std::sqrt(sum / static_cast<double>(a.size()));
}

}  // namespace facet::test
