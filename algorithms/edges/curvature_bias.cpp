#include "algorithms/edges/curvature_bias.hpp"

#include <algorithm>
#include <cmath>

namespace facet {

double curvatureBiasCoefficient(double sigma) {
  return 0.5 * sigma * sigma + 0.1;
}

std::vector<double> contourCurvatures(const std::vector<EdgePoint>& points,
                                      const std::vector<std::vector<int>>& contours,
                                      int halfWindow) {
  const int h = std::max(1, halfWindow);
  std::vector<double> kappa(points.size(), 0.0);
  for (const auto& contour : contours) {
    const int n = static_cast<int>(contour.size());
    if (n < 2 * h + 1) continue;
    // Closed contours wrap round; open ones use a one-sided window near their ends.
    const bool closed =
        cv::norm(points[contour.front()].position - points[contour.back()].position) < 1.5 &&
        n > 4 * h;
    for (int i = 0; i < n; ++i) {
      int a = i - h, b = i + h;
      if (closed) {
        a = (a + n) % n;
        b = b % n;
      } else {
        if (a < 0) b -= a, a = 0;
        if (b >= n) a -= b - (n - 1), b = n - 1;
        if (a < 0) continue;
      }
      const EdgePoint& pa = points[contour[a]];
      const EdgePoint& pb = points[contour[b]];
      const cv::Point2d dp = pb.position - pa.position;
      const double d2 = dp.dot(dp);
      if (d2 > 1e-6) kappa[contour[i]] = dp.dot(pb.normal - pa.normal) / d2;
    }
  }
  return kappa;
}

void correctCurvatureBias(std::vector<EdgePoint>& points,
                          const std::vector<std::vector<int>>& contours,
                          const CurvatureBiasParams& params) {
  const std::vector<double> kappa = contourCurvatures(points, contours, params.halfWindow);
  for (size_t i = 0; i < points.size(); ++i)
    points[i].position += params.coefficient * kappa[i] * points[i].normal;
}

}  // namespace facet
