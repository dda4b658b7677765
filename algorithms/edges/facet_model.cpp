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

// The projections of five values onto P0, P1 and P2, in integers, from their even and odd parts.
struct IntegerProjections {
  int p0, p1, p2;
};
IntegerProjections projectInteger(const int (&v)[5]) {
  const int outer = v[0] + v[4], inner = v[1] + v[3];
  return {outer + inner + v[2], 2 * (v[4] - v[0]) + (v[3] - v[1]), 2 * outer - inner - 2 * v[2]};
}

template <typename T>
FacetCoefficients fit(const cv::Mat& image, cv::Point p, double scale) {
  // Project each row onto P0..P3 in x, then the row results onto P0..P3 in y. P0..P2 have integer
  // weights: those projections, and theirs in y, are integers (exact in double too, so the
  // coefficients are the same as summing in double, with fewer instructions). P3's weights are
  // not: its sums run in double, term by term in the original order.
  int row[3][5];   // row[i][j]: row j projected onto P_i, i <= 2
  double row3[5];  // row j projected onto P3
  for (int j = 0; j < 5; ++j) {
    const T* t = image.ptr<T>(p.y - 2 + j) + (p.x - 2);
    const int v[5] = {t[0], t[1], t[2], t[3], t[4]};
    const IntegerProjections q = projectInteger(v);
    row[0][j] = q.p0;
    row[1][j] = q.p1;
    row[2][j] = q.p2;
    double s = 0;
    for (int r = 0; r < 5; ++r) s += kP[3][r] * v[r];
    row3[j] = s;
  }
  auto norm = [&](double sum, int i, int j) { return sum * scale / (kNorm[i] * kNorm[j]); };
  const IntegerProjections y0 = projectInteger(row[0]), y1 = projectInteger(row[1]),
                           y2 = projectInteger(row[2]);
  const double a00 = norm(y0.p0, 0, 0), a10 = norm(y1.p0, 1, 0), a01 = norm(y0.p1, 0, 1),
               a20 = norm(y2.p0, 2, 0), a11 = norm(y1.p1, 1, 1), a02 = norm(y0.p2, 0, 2),
               a21 = norm(y2.p1, 2, 1), a12 = norm(y1.p2, 1, 2);
  double s30 = 0, s03 = 0;
  for (int r = 0; r < 5; ++r) {
    s30 += kP[0][r] * row3[r];
    s03 += kP[3][r] * static_cast<double>(row[0][r]);
  }
  const double a30 = norm(s30, 3, 0), a03 = norm(s03, 0, 3);
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
