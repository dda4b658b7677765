#include "algorithms/edges/curvature_bias.hpp"

#include "algorithms/edges/edge_profile_fit.hpp"

#include <cmath>

namespace facet {

void correctCurvatureBias(std::vector<EdgePoint>& points,
                          const std::vector<std::vector<int>>& contours,
                          const CurvatureBiasParams& params) {
  const int h = params.halfWindow;
  std::vector<cv::Point2d> shifts;
  for (const auto& contour : contours) {
    const int n = static_cast<int>(contour.size());
    if (n < 2 * h + 1) continue;
    // Closed contours wrap round; open ones use a one-sided window near their ends.
    const EdgePoint& first = points[contour.front()];
    const EdgePoint& last = points[contour.back()];
    const bool closed = cv::norm(first.position - last.position) < 1.5 && n > 4 * h;
    shifts.assign(n, {0, 0});
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
      if (d2 < 1e-6) continue;
      const double kappa = dp.dot(pb.normal - pa.normal) / d2;
      double shift = params.coefficient * kappa;
      if (params.profileFitted) shift += std::copysign(profileCurvatureBias(kappa), kappa);
      shifts[i] = shift * points[contour[i]].normal;
    }
    for (int i = 0; i < n; ++i) points[contour[i]].position += shifts[i];
  }
}

}  // namespace facet
