#include "algorithms/scan/pose_solver.hpp"

#include <cmath>
#include <numbers>

#include <Eigen/Cholesky>

namespace facet::scan {

ScanPose solvePointToPoint(std::span<const PointPair> pairs) {
  if (pairs.empty()) return {};
  Eigen::Vector2d meanA = Eigen::Vector2d::Zero(), meanB = Eigen::Vector2d::Zero();
  for (const PointPair& p : pairs) {
    meanA += p.a;
    meanB += p.b;
  }
  meanA /= static_cast<double>(pairs.size());
  meanB /= static_cast<double>(pairs.size());
  // The best rotation turns the centred a's onto the centred b's: atan2 of the summed cross
  // and dot products.
  double cross = 0.0, dot = 0.0;
  for (const PointPair& p : pairs) {
    const Eigen::Vector2d a = p.a - meanA, b = p.b - meanB;
    cross += a.x() * b.y() - a.y() * b.x();
    dot += a.dot(b);
  }
  ScanPose pose{0.0, 0.0, std::atan2(cross, dot)};
  const Eigen::Vector2d t = meanB - pose.rotate(meanA);
  pose.x = t.x();
  pose.y = t.y();
  return pose;
}

ScanPose stepPointToLine(std::span<const PointPair> pairs, const ScanPose& current) {
  Eigen::Matrix3d H = Eigen::Matrix3d::Zero();
  Eigen::Vector3d g = Eigen::Vector3d::Zero();
  auto addRow = [&](const Eigen::Vector3d& J, double r) {
    H.noalias() += J * J.transpose();
    g.noalias() += J * r;
  };
  for (const PointPair& p : pairs) {
    const Eigen::Vector2d ra = current.rotate(p.a);
    const Eigen::Vector2d e = ra + Eigen::Vector2d(current.x, current.y) - p.b;
    const Eigen::Vector2d dTheta(-ra.y(), ra.x());  // d(R a)/d(theta)
    if (p.normal.squaredNorm() > 0.0) {
      addRow({p.normal.x(), p.normal.y(), p.normal.dot(dTheta)}, p.normal.dot(e));
    } else {
      addRow({1.0, 0.0, dTheta.x()}, e.x());
      addRow({0.0, 1.0, dTheta.y()}, e.y());
    }
  }
  H.diagonal().array() += 1e-9 * (H.trace() + 1.0);
  const Eigen::Vector3d delta = H.ldlt().solve(-g);
  return {current.x + delta(0), current.y + delta(1),
          std::remainder(current.theta + delta(2), 2.0 * std::numbers::pi)};
}

double pairRms(std::span<const PointPair> pairs, const ScanPose& pose, bool pointToLine) {
  if (pairs.empty()) return 0.0;
  double sum = 0.0;
  for (const PointPair& p : pairs) {
    const Eigen::Vector2d e = pose.apply(p.a) - p.b;
    const bool line = pointToLine && p.normal.squaredNorm() > 0.0;
    sum += line ? std::pow(p.normal.dot(e), 2) : e.squaredNorm();
  }
  return std::sqrt(sum / static_cast<double>(pairs.size()));
}

}  // namespace facet::scan
