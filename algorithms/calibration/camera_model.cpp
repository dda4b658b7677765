#include "algorithms/calibration/camera_model.hpp"

#include <cmath>

#include <opencv2/calib3d.hpp>

namespace facet {
namespace {

// OpenCV's distortion of a normalised point (same formula as projectPoints, written out so that
// single points need no Mat round trip and the Newton step below can differentiate it).
cv::Point2d distortNormalised(cv::Point2d p, const cv::Mat& d) {
  if (d.empty()) return p;
  double k[14] = {};
  const int n = static_cast<int>(d.total());
  for (int i = 0; i < n && i < 14; ++i) k[i] = d.at<double>(i);
  const double x = p.x, y = p.y, r2 = x * x + y * y, r4 = r2 * r2, r6 = r4 * r2;
  const double radial =
      (1 + k[0] * r2 + k[1] * r4 + k[4] * r6) / (1 + k[5] * r2 + k[6] * r4 + k[7] * r6);
  const double xd = x * radial + 2 * k[2] * x * y + k[3] * (r2 + 2 * x * x) + k[8] * r2 + k[9] * r4;
  const double yd =
      y * radial + k[2] * (r2 + 2 * y * y) + 2 * k[3] * x * y + k[10] * r2 + k[11] * r4;
  return {xd, yd};  // the tilted-sensor terms (tx, ty) are not supported: calibrate never sets them
}

}  // namespace

cv::Point2d CameraModel::distort(cv::Point2d normalised) const {
  const cv::Point2d d = distortNormalised(normalised, distortion);
  const auto& K = cameraMatrix;
  return {K(0, 0) * d.x + K(0, 1) * d.y + K(0, 2), K(1, 1) * d.y + K(1, 2)};
}

cv::Point2d CameraModel::project(const cv::Vec3d& c) const {
  return distort({c[0] / c[2], c[1] / c[2]});
}

cv::Point2d CameraModel::undistort(cv::Point2d pixel) const {
  const auto& K = cameraMatrix;
  // Distorted normalised target.
  const double ty = (pixel.y - K(1, 2)) / K(1, 1);
  const double tx = (pixel.x - K(0, 2) - K(0, 1) * ty) / K(0, 0);
  const cv::Point2d target{tx, ty};
  cv::Point2d p = target;
  if (distortion.empty()) return p;
  // Newton on distort(p) = target with a numeric Jacobian: converges in a few steps wherever the
  // distortion is monotonic, which a valid calibration is over its image.
  for (int it = 0; it < 30; ++it) {
    const cv::Point2d f = distortNormalised(p, distortion) - target;
    if (std::abs(f.x) < 1e-13 && std::abs(f.y) < 1e-13) break;
    const double h = 1e-7;
    const cv::Point2d fx = (distortNormalised({p.x + h, p.y}, distortion) - target - f) / h;
    const cv::Point2d fy = (distortNormalised({p.x, p.y + h}, distortion) - target - f) / h;
    const double det = fx.x * fy.y - fy.x * fx.y;
    if (std::abs(det) < 1e-12) break;
    p.x -= (fy.y * f.x - fy.x * f.y) / det;
    p.y -= (-fx.y * f.x + fx.x * f.y) / det;
  }
  return p;
}

std::vector<cv::Point2d> CameraModel::undistort(const std::vector<cv::Point2d>& pixels) const {
  std::vector<cv::Point2d> out;
  out.reserve(pixels.size());
  for (const auto& p : pixels) out.push_back(undistort(p));
  return out;
}

}  // namespace facet
