#include "algorithms/calibration/world_mapping.hpp"

#include <cmath>
#include <limits>

namespace facet {

WorldMapping::WorldMapping(CameraModel camera, PlanePose plane)
    : camera_(std::move(camera)), plane_(plane) {
  const auto& R = plane_.rotation;
  // z points into the plate, so a face `offset` above it lies at z = -offset.
  origin_ = plane_.translationMm - plane_.offsetMm * cv::Vec3d(R(0, 2), R(1, 2), R(2, 2));
}

cv::Point2d WorldMapping::toPlane(cv::Point2d pixel) const {
  const cv::Point2d n = camera_.undistort(pixel);
  const cv::Vec3d d(n.x, n.y, 1.0);
  const auto& R = plane_.rotation;
  const cv::Vec3d r1(R(0, 0), R(1, 0), R(2, 0)), r2(R(0, 1), R(1, 1), R(2, 1));
  // s d = origin + u r1 + v r2  <=>  [d | -r1 | -r2] (s, u, v) = origin
  const cv::Matx33d A(d[0], -r1[0], -r2[0], d[1], -r1[1], -r2[1], d[2], -r1[2], -r2[2]);
  const double det = cv::determinant(A);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  if (std::abs(det) < 1e-12) return {nan, nan};
  const cv::Vec3d x = A.solve(origin_, cv::DECOMP_LU);
  if (x[0] <= 0) return {nan, nan};
  return {x[1], x[2]};
}

std::vector<cv::Point2d> WorldMapping::toPlane(const std::vector<cv::Point2d>& pixels) const {
  std::vector<cv::Point2d> out;
  out.reserve(pixels.size());
  for (const auto& p : pixels) out.push_back(toPlane(p));
  return out;
}

cv::Point2d WorldMapping::toImage(cv::Point2d q) const {
  const auto& R = plane_.rotation;
  const cv::Vec3d c = origin_ + q.x * cv::Vec3d(R(0, 0), R(1, 0), R(2, 0)) +
                      q.y * cv::Vec3d(R(0, 1), R(1, 1), R(2, 1));
  return camera_.project(c);
}

double WorldMapping::mmPerPixelAt(cv::Point2d pixel) const {
  const double h = 0.5;
  const cv::Point2d a = toPlane(pixel), bx = toPlane({pixel.x + h, pixel.y}),
                    by = toPlane({pixel.x, pixel.y + h});
  const cv::Point2d ex = (bx - a) / h, ey = (by - a) / h;
  return std::sqrt(std::abs(ex.x * ey.y - ex.y * ey.x));
}

}  // namespace facet
