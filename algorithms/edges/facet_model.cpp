#include "algorithms/edges/facet_model.hpp"

#include <cmath>

namespace facet {
namespace {

// Discrete orthogonal polynomials on r = -2..2 and their squared norms.
constexpr double kP[4][5] = {{1, 1, 1, 1, 1},
                             {-2, -1, 0, 1, 2},
                             {2, -1, -2, -1, 2},          // r^2 - 2
                             {-1.2, 2.4, 0, -2.4, 1.2}};  // r^3 - 3.4 r
constexpr double kNorm[4] = {5, 10, 14, 14.4};

template <typename T>
FacetCoefficients fit(const cv::Mat& image, cv::Point p, double scale) {
  // Project each row onto P0..P3 in x, then the row results onto P0..P3 in y.
  double row[5][4];
  for (int j = 0; j < 5; ++j) {
    const T* v = image.ptr<T>(p.y - 2 + j) + (p.x - 2);
    for (int i = 0; i < 4; ++i) {
      double s = 0;
      for (int r = 0; r < 5; ++r) s += kP[i][r] * v[r];
      row[j][i] = s;
    }
  }
  auto a = [&](int i, int j) {  // coefficient of P_i(x) P_j(y)
    double s = 0;
    for (int r = 0; r < 5; ++r) s += kP[j][r] * row[r][i];
    return s * scale / (kNorm[i] * kNorm[j]);
  };
  const double a00 = a(0, 0), a10 = a(1, 0), a01 = a(0, 1), a20 = a(2, 0), a11 = a(1, 1),
               a02 = a(0, 2), a30 = a(3, 0), a21 = a(2, 1), a12 = a(1, 2), a03 = a(0, 3);
  // Expand P2 = r^2 - 2 and P3 = r^3 - 3.4 r into monomials.
  return {a00 - 2 * a20 - 2 * a02,
          a10 - 3.4 * a30 - 2 * a12,
          a01 - 3.4 * a03 - 2 * a21,
          a20,
          a11,
          a02,
          a30,
          a21,
          a12,
          a03};
}

}  // namespace

FacetCoefficients fitCubicFacet(const cv::Mat& image, cv::Point p) {
  if (image.depth() == CV_16U) return fit<ushort>(image, p, 1.0 / 256.0);
  return fit<uchar>(image, p, 1.0);
}

std::optional<FacetZeroCrossing> facetZeroCrossing(const FacetCoefficients& k) {
  const double g = std::sqrt(k[1] * k[1] + k[2] * k[2]);
  if (g <= 0) return std::nullopt;
  const double c = k[1] / g, s = k[2] / g;
  FacetZeroCrossing z;
  z.normal = {c, s};
  z.c1 = g;
  z.c2 = k[3] * c * c + k[4] * c * s + k[5] * s * s;
  z.c3 = k[6] * c * c * c + k[7] * c * c * s + k[8] * c * s * s + k[9] * s * s * s;
  if (z.c3 >= 0) return std::nullopt;
  z.rho = -z.c2 / (3 * z.c3);
  z.magnitude = z.c1 + 2 * z.c2 * z.rho + 3 * z.c3 * z.rho * z.rho;
  const double tx = -s, ty = c;  // f_xx = 2 k3, f_xy = k4, f_yy = 2 k5
  z.curvature = -(2 * k[3] * tx * tx + 2 * k[4] * tx * ty + 2 * k[5] * ty * ty) / g;
  return z;
}

std::optional<EdgePoint> facetEdgePoint(const cv::Mat& image, cv::Point p, double maxOffset) {
  const auto z = facetZeroCrossing(fitCubicFacet(image, p));
  if (!z) return std::nullopt;
  const cv::Point2d offset = z->rho * z->normal;
  if (std::abs(offset.x) > maxOffset || std::abs(offset.y) > maxOffset) return std::nullopt;
  return EdgePoint{cv::Point2d(p) + offset, z->normal, z->magnitude};
}

}  // namespace facet
