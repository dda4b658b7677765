#include "algorithms/calibration/conic.hpp"

#include <cmath>

#include <Eigen/Dense>

namespace facet {

std::optional<cv::Matx33d> fitEllipseConic(const std::vector<cv::Point2d>& points) {
  const auto n = static_cast<Eigen::Index>(points.size());
  if (n < 6) return std::nullopt;
  cv::Point2d mean(0, 0);
  for (const auto& p : points) mean += p;
  mean /= static_cast<double>(n);
  double spread = 0;
  for (const auto& p : points) spread += cv::norm(p - mean);
  spread /= static_cast<double>(n);
  if (spread <= 0) return std::nullopt;
  Eigen::MatrixXd D(n, 6);
  for (Eigen::Index i = 0; i < n; ++i) {
    const double x = (points[static_cast<std::size_t>(i)].x - mean.x) / spread;
    const double y = (points[static_cast<std::size_t>(i)].y - mean.y) / spread;
    D.row(i) << x * x, x * y, y * y, x, y, 1.0;
  }
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(D, Eigen::ComputeThinV);
  const Eigen::VectorXd a = svd.matrixV().col(5);
  const cv::Matx33d Cn(a(0), a(1) / 2, a(3) / 2, a(1) / 2, a(2), a(4) / 2, a(3) / 2, a(4) / 2,
                       a(5));
  if (a(0) * a(2) - a(1) * a(1) / 4 <= 0) return std::nullopt;  // not an ellipse
  // x_n = T x with T = [[1/s, 0, -mx/s], [0, 1/s, -my/s], [0, 0, 1]]: C = T^T Cn T.
  const cv::Matx33d T(1 / spread, 0, -mean.x / spread, 0, 1 / spread, -mean.y / spread, 0, 0, 1);
  return T.t() * Cn * T;
}

double conicDistance(const cv::Matx33d& C, cv::Point2d p) {
  const cv::Vec3d x(p.x, p.y, 1.0);
  const cv::Vec3d g = C * x;
  const double value = x.dot(g);
  const double grad = 2 * std::hypot(g[0], g[1]);
  return grad > 0 ? value / grad : 0.0;
}

cv::Point2d conicPole(const cv::Matx33d& C, const cv::Vec3d& line) {
  const cv::Vec3d x = C.inv(cv::DECOMP_SVD) * line;
  return {x[0] / x[2], x[1] / x[2]};
}

}  // namespace facet
