#include "algorithms/calibration/edge_curve.hpp"

#include <cmath>

#include <Eigen/Dense>

namespace facet {

bool fitEdgeCurve(const std::vector<cv::Point2d>& points, EdgeCurve& curve) {
  std::vector<double> t, e;
  for (const auto& p : points) {
    t.push_back((p - curve.origin).dot(curve.along));
    e.push_back((p - curve.origin).dot(curve.across));
  }
  std::vector<char> keep(points.size(), 1);
  for (int pass = 0; pass < 2; ++pass) {
    int neg = 0, pos = 0, n = 0;
    for (std::size_t i = 0; i < t.size(); ++i)
      if (keep[i]) (t[i] < 0 ? neg : pos)++, ++n;
    if (neg < 4 || pos < 4) return false;
    Eigen::MatrixXd A(n, 3);
    Eigen::VectorXd y(n);
    for (std::size_t i = 0, k = 0; i < t.size(); ++i) {
      if (!keep[i]) continue;
      A.row(static_cast<Eigen::Index>(k)) << 1.0, t[i], t[i] * t[i];
      y(static_cast<Eigen::Index>(k++)) = e[i];
    }
    const Eigen::Vector3d c = A.colPivHouseholderQr().solve(y);
    curve.a = c(0), curve.b = c(1), curve.q = c(2);
    if (pass == 1) break;
    const double rms = std::sqrt((A * c - y).squaredNorm() / n);
    const double limit = std::max(3 * rms, 0.2);
    for (std::size_t i = 0; i < t.size(); ++i)
      keep[i] = std::abs(e[i] - (c(0) + c(1) * t[i] + c(2) * t[i] * t[i])) <= limit;
  }
  return true;
}

std::optional<cv::Point2d> intersectEdgeCurves(const EdgeCurve& u, const EdgeCurve& v,
                                               cv::Point2d start) {
  cv::Point2d p = start;
  for (int it = 0; it < 8; ++it) {
    const double tu = (p - u.origin).dot(u.along), tv = (p - v.origin).dot(v.along);
    const cv::Point2d pu = u.point(tu), du = u.tangent(tu), pv = v.point(tv), dv = v.tangent(tv);
    // pu + s du = pv + w dv
    const double det = du.cross(-dv);
    if (std::abs(det) < 1e-9) return std::nullopt;
    const cv::Point2d rhs = pv - pu;
    const double s = rhs.cross(-dv) / det;
    const cv::Point2d next = pu + s * du;
    const double step = cv::norm(next - p);
    p = next;
    if (step < 1e-9) break;
  }
  return p;
}

}  // namespace facet
