#include "algorithms/registration/homography_uncertainty.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <utility>

#include "algorithms/geometry/point_normaliser.hpp"
#include "algorithms/geometry/projective_map.hpp"

namespace facet {
namespace {

int parameterCount(TransformModel model) {
  return model == TransformModel::Similarity ? 4 : model == TransformModel::Affine ? 6 : 8;
}

// Derivatives of the mapped point H p with respect to the family's parameters: (a, b, tx, ty) of
// a similarity, the first two rows of an affine map, the eight entries of a homography but
// H(2,2). Columns beyond the family's count are 0.
cv::Matx<double, 2, 8> jacobianOfMappedPoint(TransformModel model, const cv::Matx33d& H,
                                             cv::Point2d p) {
  cv::Matx<double, 2, 8> J = cv::Matx<double, 2, 8>::zeros();
  if (model == TransformModel::Similarity) {
    J(0, 0) = p.x, J(0, 1) = p.y, J(0, 2) = 1;
    J(1, 0) = p.y, J(1, 1) = -p.x, J(1, 3) = 1;
    return J;
  }
  const double w = model == TransformModel::Affine ? 1.0 : H(2, 0) * p.x + H(2, 1) * p.y + 1.0;
  J(0, 0) = p.x / w, J(0, 1) = p.y / w, J(0, 2) = 1 / w;
  J(1, 3) = p.x / w, J(1, 4) = p.y / w, J(1, 5) = 1 / w;
  if (model == TransformModel::Homography) {
    const double u = (H(0, 0) * p.x + H(0, 1) * p.y + H(0, 2)) / w;
    const double v = (H(1, 0) * p.x + H(1, 1) * p.y + H(1, 2)) / w;
    J(0, 6) = -u * p.x / w, J(0, 7) = -u * p.y / w;
    J(1, 6) = -v * p.x / w, J(1, 7) = -v * p.y / w;
  }
  return J;
}

}  // namespace

double mappedPointUncertainty(TransformModel model, const cv::Matx33d& H,
                              const std::vector<cv::Point2d>& src,
                              const std::vector<cv::Point2d>& dst,
                              const std::vector<cv::Matx22d>& errorCovariance,
                              const std::vector<cv::Point2d>& points) {
  constexpr double kUnfixed = std::numeric_limits<double>::infinity();
  const int n = parameterCount(model);
  if (2 * static_cast<int>(src.size()) < n || src.size() != dst.size() ||
      errorCovariance.size() != src.size())
    return kUnfixed;
  // The same transform between normalised coordinates (the normal matrix of pixel coordinates
  // spans fifteen orders of magnitude); a transfer error there is `scale` times the one in pixels.
  // A translation and an isotropic scale keep each family's form.
  const cv::Matx33d Ts = pointNormaliser(src), Td = pointNormaliser(dst);
  const double scale = Td(0, 0);
  cv::Matx33d Hn = Td * H * Ts.inv();
  if (std::abs(Hn(2, 2)) < 1e-12) return kUnfixed;
  Hn *= 1.0 / Hn(2, 2);
  // Accumulated in fixed-size matrices (no allocation per pair); the columns beyond the family's
  // count stay 0, and only its n x n block is inverted.
  cv::Matx<double, 8, 8> full = cv::Matx<double, 8, 8>::zeros();
  for (std::size_t i = 0; i < src.size(); ++i) {
    const cv::Matx22d C = errorCovariance[i] * (scale * scale);
    if (!(cv::determinant(C) > 0)) continue;  // a pair that told the fit nothing
    const cv::Matx<double, 2, 8> J = jacobianOfMappedPoint(model, Hn, mapPoint(Ts, src[i]));
    full += J.t() * C.inv() * J;
  }
  const cv::Mat normal = cv::Mat(full)(cv::Range(0, n), cv::Range(0, n));
  // The inverse by SVD returns the smallest singular value over the largest: all but 0 where the
  // pairs leave a direction of the transform free.
  cv::Mat inverse;
  if (!(cv::invert(normal, inverse, cv::DECOMP_SVD) > 1e-12)) return kUnfixed;
  double worst = 0;
  for (const cv::Point2d& p : points) {
    const cv::Mat J = cv::Mat(jacobianOfMappedPoint(model, Hn, mapPoint(Ts, p))).colRange(0, n);
    const cv::Mat C = J * inverse * J.t();
    // Largest eigenvalue of the symmetric 2x2 covariance.
    const double a = C.at<double>(0, 0), b = C.at<double>(0, 1), d = C.at<double>(1, 1);
    const double largest = 0.5 * (a + d) + std::hypot(0.5 * (a - d), b);
    worst = std::max(worst, std::sqrt(std::max(0.0, largest)));
  }
  return worst / scale;
}

double sharedErrorFactor(const std::vector<cv::Point2d>& src,
                         const std::vector<cv::Point2d>& residual, double radius) {
  if (src.size() < 2 || residual.size() != src.size() || !(radius > 0)) return 1.0;
  // Pairs bucketed in cells of `radius`: the neighbours of a pair lie in its cell's 3 x 3 block.
  double x0 = src[0].x, y0 = src[0].y;
  for (const cv::Point2d& p : src) x0 = std::min(x0, p.x), y0 = std::min(y0, p.y);
  std::map<std::pair<long, long>, std::vector<std::size_t>> cells;
  const auto cellOf = [&](cv::Point2d p) {
    return std::pair<long, long>(std::lround(std::floor((p.x - x0) / radius)),
                                 std::lround(std::floor((p.y - y0) / radius)));
  };
  for (std::size_t i = 0; i < src.size(); ++i) cells[cellOf(src[i])].push_back(i);
  double shared = 0, own = 0;
  std::size_t neighbours = 0;
  for (std::size_t i = 0; i < src.size(); ++i) {
    own += residual[i].dot(residual[i]);
    const auto [cx, cy] = cellOf(src[i]);
    for (long dx = -1; dx <= 1; ++dx)
      for (long dy = -1; dy <= 1; ++dy) {
        const auto cell = cells.find({cx + dx, cy + dy});
        if (cell == cells.end()) continue;
        for (std::size_t j : cell->second)
          if (j != i && cv::norm(src[j] - src[i]) <= radius) {
            shared += residual[i].dot(residual[j]);
            ++neighbours;
          }
      }
  }
  if (neighbours == 0 || !(own > 0)) return 1.0;
  const double n = static_cast<double>(src.size());
  const double rho = (shared / static_cast<double>(neighbours)) / (own / n);
  return std::max(1.0, 1.0 + (static_cast<double>(neighbours) / n) * rho);
}

double mappedPointUncertainty(TransformModel model, const cv::Matx33d& H,
                              const std::vector<cv::Point2d>& src,
                              const std::vector<cv::Point2d>& dst, double noise,
                              const std::vector<cv::Point2d>& points) {
  const std::vector<cv::Matx22d> covariance(src.size(), cv::Matx22d::eye() * (noise * noise));
  return mappedPointUncertainty(model, H, src, dst, covariance, points);
}

}  // namespace facet
