#include "algorithms/shape/least_squares_refinement.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

#include <Eigen/Dense>

#include "algorithms/edges/subpixel_edges.hpp"

namespace facet::shape_detail {

Refined refineLeastSquares(const cv::Mat& image, const ShapeModel& model, cv::Rect roi, Pose2D pose,
                           Polarity polarity, bool withScale) {
  const Pose2D start = pose;
  Refined result{pose, 0.0, {RefinementFailure::TooFewCorrespondences, {}}};
  roi &= cv::Rect(0, 0, image.cols, image.rows);
  if (roi.width < 3 || roi.height < 3) return result;
  EdgeParams edgeParams;
  edgeParams.roi = roi;
  edgeParams.low = model.minContrast;
  edgeParams.high = std::max(2.0 * model.minContrast, 0.5 * model.contrastHigh);
  edgeParams.fitProfile = model.edgeEstimator == EdgeEstimator::ProfileFit;
  const EdgeContours edges = detectSubpixelEdges(image, edgeParams);
  if (edges.points.size() < 6) return result;

  // Edge points indexed by the pixel that holds them.
  cv::Mat cell(roi.size(), CV_32S, cv::Scalar(-1));
  for (int i = 0; i < static_cast<int>(edges.points.size()); ++i) {
    const cv::Point p(cvRound(edges.points[i].position.x) - roi.x,
                      cvRound(edges.points[i].position.y) - roi.y);
    if (!cv::Rect(0, 0, roi.width, roi.height).contains(p)) continue;
    int& slot = cell.at<int>(p);
    if (slot < 0 || edges.points[slot].magnitude < edges.points[i].magnitude) slot = i;
  }

  constexpr double kMinCos = 0.8;  // direction agreement of a correspondence (about 37 degrees)
  double sign = 1.0;               // global polarity, decided on the first pass
  const int unknowns = withScale ? 4 : 3;
  struct Pair {
    Eigen::Vector4d J;
    double r;
  };
  std::vector<Pair> pairs;
  // Each model point placed by `at` paired with the nearest direction-agreeing edge point within
  // `radius` pixels; returns the sum of the pairs' direction agreements (the global polarity).
  const auto correspond = [&](const Pose2D& at, int radius, bool anySign) {
    const double c = std::cos(at.angle), s = std::sin(at.angle);
    const Pose2D::Map toImage = at.map();
    double polaritySum = 0.0;
    pairs.clear();
    for (const auto& mp : model.finePoints) {
      const double px = mp.position.x, py = mp.position.y;
      const cv::Point2d q = toImage({px, py});
      const double dx = c * mp.direction.x + s * mp.direction.y;
      const double dy = -s * mp.direction.x + c * mp.direction.y;
      const int cx = cvRound(q.x) - roi.x, cy = cvRound(q.y) - roi.y;
      int bestIdx = -1;
      double bestD2 = 1e30, bestDot = 0.0;
      const int u0 = std::max(cx - radius, 0), u1 = std::min(cx + radius, roi.width - 1);
      const int v0 = std::max(cy - radius, 0), v1 = std::min(cy + radius, roi.height - 1);
      for (int v = v0; v <= v1; ++v) {
        const int* row = cell.ptr<int>(v);
        for (int u = u0; u <= u1; ++u) {
          if (row[u] < 0) continue;
          const EdgePoint& e = edges.points[row[u]];
          const double dot = e.normal.x * dx + e.normal.y * dy;
          const double agree = polarity == Polarity::IgnoreLocal    ? std::abs(dot)
                               : polarity == Polarity::IgnoreGlobal ? sign * dot
                                                                    : dot;
          if (agree < kMinCos && !(anySign && std::abs(dot) >= kMinCos)) continue;
          const double d2 = (e.position.x - q.x) * (e.position.x - q.x) +
                            (e.position.y - q.y) * (e.position.y - q.y);
          if (d2 < bestD2) bestD2 = d2, bestIdx = row[u], bestDot = dot;
        }
      }
      if (bestIdx < 0) continue;
      polaritySum += bestDot;
      const EdgePoint& e = edges.points[bestIdx];
      const double r = e.normal.x * (q.x - e.position.x) + e.normal.y * (q.y - e.position.y);
      // q = t + s R(a) p: dq/da = s R'(a) p, dq/ds = R(a) p.
      const double rpx = c * px + s * py, rpy = -s * px + c * py;
      pairs.push_back(
          {Eigen::Vector4d(e.normal.x, e.normal.y, at.scale * (e.normal.x * rpy - e.normal.y * rpx),
                           e.normal.x * rpx + e.normal.y * rpy),
           r});
    }
    return polaritySum;
  };
  // How well model points lie on image edges at `at`: each point within a pixel of an edge
  // (across it) counts by Tukey's biweight of its distance, 1 on the edge, 0 a pixel away. A
  // correlation score cannot tell a pose that fits the part from one tilted towards a displaced
  // feature (a hole out of place): both overlap the edges within the score's tolerance of a
  // pixel or two, and the tilted one may overlap more. A smooth weight, not a count within a
  // threshold: two poses a few hundredths of a pixel apart must not be ranked by noise.
  const auto support = [&](const Pose2D& at) {
    correspond(at, 1, false);
    double sum = 0.0;
    for (const auto& pr : pairs)
      if (std::abs(pr.r) < 1.0) sum += (1.0 - pr.r * pr.r) * (1.0 - pr.r * pr.r);
    return sum;
  };

  std::vector<double> absResiduals;
  for (int iteration = 0; iteration < 15; ++iteration) {
    const int radius = iteration < 2 ? 3 - iteration : 1;
    const double polaritySum =
        correspond(pose, radius, iteration == 0 && polarity == Polarity::IgnoreGlobal);
    if (iteration == 0 && polarity == Polarity::IgnoreGlobal) sign = polaritySum < 0 ? -1.0 : 1.0;
    if (pairs.size() < 6) break;  // result keeps the last pose that stood on enough pairs

    // Robust weights: Huber while the pose is coarse, then Tukey's biweight with a cut-off from
    // the median residual, so that edges of occluders and clutter drop out entirely.
    absResiduals.clear();
    for (const auto& pr : pairs) absResiduals.push_back(std::abs(pr.r));
    auto mid = absResiduals.begin() + static_cast<std::ptrdiff_t>(absResiduals.size() / 2);
    std::nth_element(absResiduals.begin(), mid, absResiduals.end());
    const double cutoff = std::clamp(4.685 * 1.4826 * *mid, 0.15, 1.5);
    Eigen::Matrix4d H = Eigen::Matrix4d::Zero();
    Eigen::Vector4d g = Eigen::Vector4d::Zero();
    double sumSq = 0.0, weightSum = 0.0;
    for (const auto& pr : pairs) {
      const double a = std::abs(pr.r);
      double w = 0.0;
      if (iteration < 2) {
        w = a <= 0.5 ? 1.0 : 0.5 / a;
      } else if (a < cutoff) {
        const double t = 1.0 - (a / cutoff) * (a / cutoff);
        w = t * t;
      }
      // The lower triangle only: the LDLT solve below reads no other part of H.
      const Eigen::Vector4d wJ = w * pr.J;
      for (int j = 0; j < 4; ++j)
        for (int i = j; i < 4; ++i) H(i, j) += pr.J[j] * wJ[i];
      g += w * pr.r * pr.J;
      sumSq += w * pr.r * pr.r;
      weightSum += w;
    }
    if (weightSum < 6.0) break;
    Eigen::VectorXd delta = H.topLeftCorner(unknowns, unknowns).ldlt().solve(-g.head(unknowns));
    if (!delta.allFinite()) break;
    pose.x += delta[0];
    pose.y += delta[1];
    pose.angle += delta[2];
    if (withScale) pose.scale += delta[3];
    result = {pose, std::sqrt(sumSq / weightSum), {}};
    if (iteration >= 3 && std::hypot(delta[0], delta[1]) < 1e-4 && std::abs(delta[2]) < 1e-6) break;
  }
  result.pose.angle = wrapAngle(result.pose.angle);
  if (result.status.ok()) {
    result.support = support(result.pose);
    result.startSupport = support(start);
  }
  return result;
}

}  // namespace facet::shape_detail
