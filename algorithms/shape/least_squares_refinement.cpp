#include "algorithms/shape/least_squares_refinement.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

#include <Eigen/Dense>
#include <opencv2/imgproc.hpp>

namespace facet::shape_detail {

namespace {
constexpr double kMinCos = 0.8;  // direction agreement of a correspondence (about 37 degrees)
// The profile fit is most of a refinement's edge detection, and a large template's region holds
// many edges far from its contour (texture, other parts) that no fit ever pairs: a model point is
// paired within 3 px of where the pose places it, a fit that moves the part 3 px or more is
// refused (find_shape_model.cpp), and a point's curvature correction reads 8 points either side
// along its contour. So only edges within this many pixels of the contour placed at the start are
// fitted, plus what the largest scale change a fit may make moves the farthest points. A
// bracket's whole region lies in that band; a 1126x973 template's region does not.
constexpr int kBandPixels = 16;
}  // namespace

template <int Radius>
double LeastSquaresRefinement::correspondWithin(const Pose2D& at, bool anySign, double sign,
                                                std::vector<Pair>& pairs,
                                                const std::vector<std::uint8_t>& visible) const {
  static_assert(Radius >= 1 && 2 * Radius <= kCellBorder);
  const double c = std::cos(at.angle), s = std::sin(at.angle);
  const Pose2D::Map toImage = at.map();
  double polaritySum = 0.0;
  pairs.clear();
  for (std::size_t i = 0; i < model_.finePoints.size(); ++i) {
    if (!visible.empty() && !visible[i]) continue;
    const auto& mp = model_.finePoints[i];
    const double px = mp.position.x, py = mp.position.y;
    const cv::Point2d q = toImage({px, py});
    const int cx = cvRound(q.x) - roi_.x, cy = cvRound(q.y) - roi_.y;
    // A window that meets the region lies within its frame of empty cells (2 Radius wide at
    // most): it is scanned whole, with no clipping, in the same order.
    if (cx < -Radius || cy < -Radius || cx >= roi_.width + Radius || cy >= roi_.height + Radius)
      continue;
    const double dx = c * mp.direction.x + s * mp.direction.y;
    const double dy = -s * mp.direction.x + c * mp.direction.y;
    int bestIdx = -1;
    double bestD2 = 1e30, bestDot = 0.0;
    for (int v = cy - Radius; v <= cy + Radius; ++v) {
      const int* row = cell_.ptr<int>(v + kCellBorder) + kCellBorder;
      for (int u = cx - Radius; u <= cx + Radius; ++u) {
        if (row[u] < 0) continue;
        const EdgePoint& e = edges_.points[row[u]];
        const double dot = e.normal.x * dx + e.normal.y * dy;
        const double agree = polarity_ == Polarity::IgnoreLocal    ? std::abs(dot)
                             : polarity_ == Polarity::IgnoreGlobal ? sign * dot
                                                                   : dot;
        if (agree < kMinCos && !(anySign && std::abs(dot) >= kMinCos)) continue;
        const double d2 = (e.position.x - q.x) * (e.position.x - q.x) +
                          (e.position.y - q.y) * (e.position.y - q.y);
        if (d2 < bestD2) bestD2 = d2, bestIdx = row[u], bestDot = dot;
      }
    }
    if (bestIdx < 0) continue;
    polaritySum += bestDot;
    const EdgePoint& e = edges_.points[bestIdx];
    const double r = e.normal.x * (q.x - e.position.x) + e.normal.y * (q.y - e.position.y);
    // q = t + s R(a) p: dq/da = s R'(a) p, dq/ds = R(a) p.
    const double rpx = c * px + s * py, rpy = -s * px + c * py;
    pairs.push_back(
        {Eigen::Vector4d(e.normal.x, e.normal.y, at.scale * (e.normal.x * rpy - e.normal.y * rpx),
                         e.normal.x * rpx + e.normal.y * rpy),
         r});
  }
  return polaritySum;
}

cv::Mat LeastSquaresRefinement::contourBand(const std::vector<Pose2D>& starts,
                                            double scaleFreedom) const {
  double reach = 0.0, scale = 0.0;
  for (const auto& mp : model_.finePoints)
    reach = std::max(reach, std::hypot(double(mp.position.x), double(mp.position.y)));
  for (const Pose2D& start : starts) scale = std::max(scale, start.scale);
  const int r = kBandPixels + static_cast<int>(std::ceil(scaleFreedom * reach * scale));
  // Cells of r x r pixels: a pixel within r of a point lies in the point's cell or a neighbour,
  // so the cells next to those holding points cover the band (and a little more), at the cost
  // of marking them (a dilation of the region by 2r + 1 cost a refinement 3%).
  const cv::Size cells((roi_.width + r - 1) / r, (roi_.height + r - 1) / r);
  cv::Mat held(cells, CV_8U, cv::Scalar(0));
  for (const Pose2D& start : starts) {
    const Pose2D::Map toImage = start.map();
    for (const auto& mp : model_.finePoints) {
      const cv::Point2d q = toImage({mp.position.x, mp.position.y});
      const int cx = static_cast<int>(std::floor((q.x - roi_.x) / r));
      const int cy = static_cast<int>(std::floor((q.y - roi_.y) / r));
      if (cx >= 0 && cy >= 0 && cx < cells.width && cy < cells.height) held.at<uchar>(cy, cx) = 1;
    }
  }
  cv::dilate(held, held, cv::Mat());  // and their neighbours (3x3)
  // Where the band is most of the region (a bracket's), the mask would save less than it costs.
  if (4 * cv::countNonZero(held) >= 3 * static_cast<int>(held.total())) return {};
  cv::Mat band(roi_.size(), CV_8U, cv::Scalar(0));
  for (int y = 0; y < cells.height; ++y)
    for (int x = 0; x < cells.width; ++x)
      if (held.at<uchar>(y, x))
        band(cv::Rect(x * r, y * r, r, r) & cv::Rect(0, 0, roi_.width, roi_.height)).setTo(255);
  return band;
}

LeastSquaresRefinement::LeastSquaresRefinement(const cv::Mat& image, const ShapeModel& model,
                                               cv::Rect roi, Polarity polarity,
                                               const std::vector<Pose2D>& starts,
                                               double scaleFreedom)
    : model_(model), polarity_(polarity), roi_(roi & cv::Rect(0, 0, image.cols, image.rows)) {
  if (roi_.width < 3 || roi_.height < 3) return;
  EdgeParams edgeParams;
  edgeParams.roi = roi_;
  edgeParams.fitMask = contourBand(starts, scaleFreedom);
  edgeParams.low = model.minContrast;
  edgeParams.high = std::max(2.0 * model.minContrast, 0.5 * model.contrastHigh);
  edgeParams.fitProfile = model.edgeEstimator == EdgeEstimator::ProfileFit;
  edges_ = detectSubpixelEdges(image, edgeParams);

  // Edge points indexed by the pixel that holds them, in a frame of kCellBorder empty cells.
  cell_ =
      cv::Mat(roi_.height + 2 * kCellBorder, roi_.width + 2 * kCellBorder, CV_32S, cv::Scalar(-1));
  for (int i = 0; i < static_cast<int>(edges_.points.size()); ++i) {
    const cv::Point p(cvRound(edges_.points[i].position.x) - roi_.x,
                      cvRound(edges_.points[i].position.y) - roi_.y);
    if (!cv::Rect(0, 0, roi_.width, roi_.height).contains(p)) continue;
    int& slot = cell_.at<int>(p.y + kCellBorder, p.x + kCellBorder);
    if (slot < 0 || edges_.points[slot].magnitude < edges_.points[i].magnitude) slot = i;
  }
}

double LeastSquaresRefinement::correspond(const Pose2D& at, int radius, bool anySign, double sign,
                                          std::vector<Pair>& pairs,
                                          const std::vector<std::uint8_t>& visible) const {
  switch (radius) {
    case 1:
      return correspondWithin<1>(at, anySign, sign, pairs, visible);
    case 2:
      return correspondWithin<2>(at, anySign, sign, pairs, visible);
    case 3:
      return correspondWithin<3>(at, anySign, sign, pairs, visible);
    default:
      throw std::logic_error("LeastSquaresRefinement: a correspondence radius of 1-3 pixels");
  }
}

// A smooth weight, not a count within a threshold: two poses a few hundredths of a pixel apart
// must not be ranked by noise.
double LeastSquaresRefinement::support(const Pose2D& at, double sign, double cutoff) const {
  std::vector<Pair> pairs;
  correspond(at, 1, false, sign, pairs);
  double sum = 0.0;
  for (const auto& pr : pairs) {
    const double u = pr.r / cutoff;
    if (std::abs(u) < 1.0) sum += (1.0 - u * u) * (1.0 - u * u);
  }
  return sum;
}

double LeastSquaresRefinement::support(const Refined& fit, double cutoff) const {
  return support(fit.pose, fit.contrastSign, cutoff);
}

Refined LeastSquaresRefinement::refine(Pose2D pose, bool withScale,
                                       const std::vector<std::uint8_t>& visible) const {
  const Pose2D start = pose;
  Refined result{pose, 0.0, {RefinementFailure::TooFewCorrespondences, {}}};
  if (edges_.points.size() < 6) return result;

  const int unknowns = withScale ? 4 : 3;
  const bool decideSign = polarity_ == Polarity::IgnoreGlobal;
  double sign = 1.0;  // global polarity, decided on the first pass
  std::vector<Pair> pairs;
  std::vector<double> absResiduals;
  for (int iteration = 0; iteration < 15; ++iteration) {
    const int radius = iteration < 2 ? 3 - iteration : 1;
    const double polaritySum =
        correspond(pose, radius, iteration == 0 && decideSign, sign, pairs, visible);
    if (iteration == 0 && decideSign) sign = polaritySum < 0 ? -1.0 : 1.0;
    if (pairs.size() < 6) break;  // result keeps the last pose that stood on enough pairs

    // Robust weights: Huber while the pose is coarse, then Tukey's biweight with a cut-off from
    // the median residual, so that edges of occluders and clutter drop out entirely.
    absResiduals.clear();
    for (const auto& pr : pairs) absResiduals.push_back(std::abs(pr.r));
    auto mid = absResiduals.begin() + static_cast<std::ptrdiff_t>(absResiduals.size() / 2);
    std::nth_element(absResiduals.begin(), mid, absResiduals.end());
    const double cutoff = std::clamp(4.685 * 1.4826 * *mid, kMinCutoff, kMaxCutoff);
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
    result = {pose, std::sqrt(sumSq / weightSum), {}, 0.0, 0.0, cutoff, 0.0, sign};
    if (withScale) {
      // Covariance of the step: residual^2 (J^T W J)^-1.
      const Eigen::Matrix4d inverse = Eigen::Matrix4d(H.selfadjointView<Eigen::Lower>())
                                          .ldlt()
                                          .solve(Eigen::Matrix4d::Identity());
      result.scaleSigma = result.residual * std::sqrt(std::max(inverse(3, 3), 0.0)) / pose.scale;
    }
    if (iteration >= 3 && std::hypot(delta[0], delta[1]) < 1e-4 && std::abs(delta[2]) < 1e-6) break;
  }
  result.pose.angle = wrapAngle(result.pose.angle);
  if (result.status.ok()) {
    // A point within a pixel of an edge counts: a correlation score cannot tell a pose that fits
    // the part from one tilted towards a displaced feature (a hole out of place): both overlap
    // the edges within the score's tolerance of a pixel or two, and the tilted one may overlap
    // more.
    result.support = support(result.pose, sign, 1.0);
    result.startSupport = support(start, sign, 1.0);
  }
  return result;
}

}  // namespace facet::shape_detail
