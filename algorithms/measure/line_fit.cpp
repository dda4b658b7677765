#include "algorithms/measure/line_fit.hpp"

#include <algorithm>
#include <cmath>

#include "algorithms/geometry/ransac.hpp"

namespace facet {
namespace {

struct Line {
  cv::Point2d point, direction;
};

double distance(const Line& l, cv::Point2d p) {
  const cv::Point2d d = p - l.point;
  return std::abs(d.x * l.direction.y - d.y * l.direction.x);
}

// Weighted orthogonal least squares: centroid and the principal axis of the scatter.
std::optional<Line> weightedFit(const std::vector<cv::Point2d>& pts, const std::vector<double>& w) {
  double sw = 0, mx = 0, my = 0;
  for (std::size_t i = 0; i < pts.size(); ++i)
    sw += w[i], mx += w[i] * pts[i].x, my += w[i] * pts[i].y;
  if (sw <= 0) return std::nullopt;
  mx /= sw, my /= sw;
  double sxx = 0, sxy = 0, syy = 0;
  for (std::size_t i = 0; i < pts.size(); ++i) {
    const double dx = pts[i].x - mx, dy = pts[i].y - my;
    sxx += w[i] * dx * dx, sxy += w[i] * dx * dy, syy += w[i] * dy * dy;
  }
  const double theta = 0.5 * std::atan2(2 * sxy, sxx - syy);  // major axis
  return Line{{mx, my}, {std::cos(theta), std::sin(theta)}};
}

double median(std::vector<double> v) {
  const auto mid = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
  std::nth_element(v.begin(), mid, v.end());
  return *mid;
}

}  // namespace

std::optional<FittedLine> fitLineRobust(const std::vector<cv::Point2d>& pts,
                                        const LineFitParams& params) {
  if (pts.size() < 3) return std::nullopt;
  RansacParams rp;
  rp.inlierThreshold = params.ransacThreshold;
  const auto consensus = ransac<Line>(
      pts.size(), 2,
      [&](const std::vector<std::size_t>& s) -> std::optional<Line> {
        const cv::Point2d d = pts[s[1]] - pts[s[0]];
        const double n = std::hypot(d.x, d.y);
        if (n < 1e-9) return std::nullopt;
        return Line{pts[s[0]], d / n};
      },
      [&](const Line& l, std::size_t i) { return distance(l, pts[i]); }, rp);
  if (!consensus || consensus->inliers.size() < 3) return std::nullopt;

  std::vector<double> w(pts.size(), 0.0);
  for (std::size_t i : consensus->inliers) w[i] = 1.0;
  std::optional<Line> line = weightedFit(pts, w);
  double cutoff = params.ransacThreshold;
  for (int it = 0; it < params.iterations && line; ++it) {
    std::vector<double> r;
    for (std::size_t i = 0; i < pts.size(); ++i)
      if (distance(*line, pts[i]) <= cutoff) r.push_back(distance(*line, pts[i]));
    if (r.size() < 3) return std::nullopt;
    const double scale = std::max(params.minScale, 1.4826 * median(r));
    cutoff = std::min(params.ransacThreshold, 4.685 * scale);  // Tukey's biweight
    for (std::size_t i = 0; i < pts.size(); ++i) {
      const double u = distance(*line, pts[i]) / cutoff;
      w[i] = u < 1 ? (1 - u * u) * (1 - u * u) : 0.0;
    }
    line = weightedFit(pts, w);
  }
  if (!line) return std::nullopt;
  FittedLine out{line->point, line->direction, {}, 0, 0};
  double ss = 0;
  for (std::size_t i = 0; i < pts.size(); ++i) {
    if (w[i] <= 0) continue;
    const double r = distance(*line, pts[i]);
    out.inliers.push_back(static_cast<int>(i));
    ss += r * r;
    out.straightness = std::max(out.straightness, r);
  }
  if (out.inliers.size() < 3) return std::nullopt;
  out.rms = std::sqrt(ss / static_cast<double>(out.inliers.size()));
  return out;
}

LineSegment inlierSegment(const FittedLine& line, const std::vector<cv::Point2d>& points,
                          cv::Point2d towards) {
  const cv::Point2d dir = line.direction.dot(towards) < 0 ? -line.direction : line.direction;
  double t0 = 1e300, t1 = -1e300;
  for (int i : line.inliers) {
    const double t = (points[static_cast<std::size_t>(i)] - line.point).dot(dir);
    t0 = std::min(t0, t), t1 = std::max(t1, t);
  }
  return {line.point + t0 * dir, line.point + t1 * dir, dir};
}

}  // namespace facet
