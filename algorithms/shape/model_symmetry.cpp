#include "algorithms/shape/model_symmetry.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "algorithms/shape/level_search.hpp"
#include "algorithms/shape/response_map_search.hpp"
#include "algorithms/shape/shape_model.hpp"

namespace facet {
namespace {

constexpr double kTwoPi = 2.0 * std::numbers::pi;
// The sample that scores every turn first, and how far below the threshold its score may lie
// for the turn to be scored with all points (a sample of ~100 points misses the full share by
// a few hundredths at most; the margin is several times that).
constexpr std::size_t kSampledPoints = 100;
constexpr double kSampleMargin = 0.15;

// The model's points rasterised around their centre: the unit direction at every point's pixel,
// zero elsewhere, so that a turned point's neighbourhood can be looked up directly.
struct PointRaster {
  cv::Mat directions;  // CV_32FC2
  cv::Point2d origin;  // model coordinates of pixel (0, 0)
};

PointRaster rasterise(const std::vector<ShapePoint>& points, cv::Point2d centre, double reach) {
  const int side = 2 * static_cast<int>(std::ceil(reach)) + 5;
  PointRaster r{cv::Mat(side, side, CV_32FC2, cv::Scalar(0, 0)),
                centre - cv::Point2d((side - 1) / 2.0, (side - 1) / 2.0)};
  for (const auto& p : points) {
    const cv::Point at(cvRound(p.position.x - r.origin.x), cvRound(p.position.y - r.origin.y));
    if (cv::Rect(0, 0, side, side).contains(at))
      r.directions.at<cv::Vec2f>(at) = {p.direction.x, p.direction.y};
  }
  return r;
}

// Mean over every `stride`-th point of the best direction agreement within one pixel of the
// point turned by `angle` about `centre` and moved by `shift`.
double selfSimilarity(const std::vector<ShapePoint>& points, const PointRaster& raster,
                      cv::Point2d centre, double angle, std::size_t stride = 1,
                      cv::Point2d shift = {}) {
  const double c = std::cos(angle), s = std::sin(angle);
  const cv::Rect inside(1, 1, raster.directions.cols - 2, raster.directions.rows - 2);
  double sum = 0.0;
  std::size_t used = 0;
  for (std::size_t i = 0; i < points.size(); i += stride, ++used) {
    const ShapePoint& p = points[i];
    const double x = p.position.x - centre.x, y = p.position.y - centre.y;
    const cv::Point2d q = centre + shift + cv::Point2d(c * x + s * y, -s * x + c * y);
    const cv::Point at(cvRound(q.x - raster.origin.x), cvRound(q.y - raster.origin.y));
    if (!inside.contains(at)) continue;
    const double dx = c * p.direction.x + s * p.direction.y;
    const double dy = -s * p.direction.x + c * p.direction.y;
    double best = 0.0;
    for (int v = -1; v <= 1; ++v)
      for (int u = -1; u <= 1; ++u) {
        const cv::Vec2f d = raster.directions.at<cv::Vec2f>(at + cv::Point(u, v));
        best = std::max(best, d[0] * dx + d[1] * dy);
      }
    sum += best;
  }
  return used == 0 ? 0.0 : sum / static_cast<double>(used);
}

// The turn of `points` near `angle` (within `angleReach`, in steps of `angleStep`) and the shift
// within `shiftReach` pixels (in whole pixels) about `centre` that maps them best onto themselves.
struct Turn {
  double angle;
  cv::Point2d shift;
  double score;
};
Turn bestTurnNear(const std::vector<ShapePoint>& points, const PointRaster& raster,
                  cv::Point2d centre, Turn start, double angleReach, double angleStep,
                  int shiftReach, std::size_t stride) {
  Turn best{start.angle, start.shift, -1.0};
  const int steps = static_cast<int>(std::ceil(angleReach / angleStep));
  for (int k = -steps; k <= steps; ++k)
    for (int dy = -shiftReach; dy <= shiftReach; ++dy)
      for (int dx = -shiftReach; dx <= shiftReach; ++dx) {
        const double a = start.angle + k * angleStep;
        const cv::Point2d shift = start.shift + cv::Point2d(dx, dy);
        const double v = selfSimilarity(points, raster, centre, a, stride, shift);
        if (v > best.score) best = {a, shift, v};
      }
  return best;
}

// Model points about their centroid, rasterised.
struct Cloud {
  cv::Point2d centre;
  double reach = 0.0;  // farthest point from the centre, pixels
  PointRaster raster;
};
Cloud cloudOf(const std::vector<ShapePoint>& points) {
  cv::Point2d centre(0, 0);
  for (const auto& p : points) centre += cv::Point2d(p.position.x, p.position.y);
  centre *= 1.0 / static_cast<double>(points.size());
  double reach = 0.0;
  for (const auto& p : points)
    reach = std::max(reach, std::hypot(p.position.x - centre.x, p.position.y - centre.y));
  return {centre, reach, rasterise(points, centre, reach)};
}

}  // namespace

std::vector<ModelSymmetry> findModelSymmetries(const std::vector<ShapePoint>& points,
                                               double angleStep, double minScore, int maxCount) {
  if (points.size() < 8 || !(angleStep > 0.0)) return {};
  const Cloud cloud = cloudOf(points);
  const cv::Point2d centre = cloud.centre;
  const PointRaster& raster = cloud.raster;

  const int n = std::max(8, static_cast<int>(std::ceil(kTwoPi / angleStep)));
  // Every angle is scored with a sample of the points first (a model has hundreds and the turn
  // has a thousand steps: this ran ~8 ms at every model load). Where the sample comes near the
  // threshold, the steps around are scored with all points, which decide as before.
  const std::size_t stride = std::max<std::size_t>(1, points.size() / kSampledPoints);
  std::vector<double> sampled(static_cast<std::size_t>(n));
  for (int k = 0; k < n; ++k)
    sampled[k] = selfSimilarity(points, raster, centre, k * kTwoPi / n, stride);
  std::vector<double> score(static_cast<std::size_t>(n), -1.0);  // all points; -1 = not scored
  const auto full = [&](int k) {
    k = (k % n + n) % n;
    if (score[k] < 0) score[k] = selfSimilarity(points, raster, centre, k * kTwoPi / n);
    return score[k];
  };
  const double sampledMargin = stride > 1 ? kSampleMargin : 0.0;
  // Local maxima away from the identity (its own peak is several steps wide).
  std::vector<ModelSymmetry> out;
  const int guard = std::max(3, n / 36);
  for (int k = guard; k <= n - guard; ++k) {
    if (sampled[k] < minScore - sampledMargin) continue;
    const double v = full(k);
    if (v < minScore || v < full(k - 1) || v < full(k + 1)) continue;
    out.push_back({wrapAngle(k * kTwoPi / n), centre, v});
  }
  std::sort(out.begin(), out.end(),
            [](const ModelSymmetry& a, const ModelSymmetry& b) { return a.score > b.score; });
  if (static_cast<int>(out.size()) > maxCount) out.resize(static_cast<std::size_t>(maxCount));
  return out;
}

bool mapsOntoItselfAtEveryTurn(const std::vector<ShapePoint>& points, double angleStep,
                               double minScore) {
  if (points.size() < 8 || !(angleStep > 0.0)) return false;
  const Cloud cloud = cloudOf(points);
  const int n = std::max(8, static_cast<int>(std::ceil(kTwoPi / angleStep)));
  const int guard = std::max(3, n / 36);  // as findModelSymmetries: the identity's own peak
  for (int k = guard; k <= n / 2; ++k)
    if (selfSimilarity(points, cloud.raster, cloud.centre, k * kTwoPi / n) < minScore) return false;
  return true;
}

std::vector<ModelSymmetry> findSearchSymmetries(const std::vector<ShapeLevel>& levels) {
  if (levels.empty()) return {};
  const ShapeLevel& base = levels.front();
  std::vector<ModelSymmetry> out = findModelSymmetries(base.points, base.angleStep);
  const ShapeLevel& top = levels.back();
  if (levels.size() < 2 || base.points.size() < 8 || top.points.size() < 8) return out;
  const double f = std::ldexp(1.0, static_cast<int>(levels.size()) - 1);
  const Cloud topCloud = cloudOf(top.points), baseCloud = cloudOf(base.points);
  for (const ModelSymmetry& coarse : findModelSymmetries(top.points, top.angleStep)) {
    const bool known = std::any_of(out.begin(), out.end(), [&](const ModelSymmetry& s) {
      return std::abs(wrapAngle(s.angle - coarse.angle)) <= top.angleStep;
    });
    if (known) continue;
    // The centroid of the points is not the centre of the part's symmetry where a feature breaks
    // it (a lens ring off the centre of a rectangular housing): find the turn's shift too, on the
    // top level (coarse, cheap), then on level 0 around it (a sample of the points, then all).
    const int topShift = std::max(2, static_cast<int>(std::ceil(topCloud.reach / 3.0)));
    Turn t = bestTurnNear(top.points, topCloud.raster, topCloud.centre, {coarse.angle, {}, 0.0},
                          top.angleStep, 0.5 * top.angleStep, topShift, 1);
    // The same turn and shift about level 0's centroid (model coordinates are level 0's times
    // 1/f on the top level).
    const double c = std::cos(t.angle), s = std::sin(t.angle);
    const cv::Point2d m = baseCloud.centre, mt = topCloud.centre * f;
    const cv::Point2d d = mt - m;
    const cv::Point2d shift0 = t.shift * f + d - cv::Point2d(c * d.x + s * d.y, -s * d.x + c * d.y);
    const std::size_t stride = std::max<std::size_t>(1, base.points.size() / kSampledPoints);
    Turn fine = bestTurnNear(base.points, baseCloud.raster, m,
                             {t.angle, {std::round(shift0.x), std::round(shift0.y)}, 0.0},
                             0.5 * top.angleStep, base.angleStep, static_cast<int>(f / 2), stride);
    fine =
        bestTurnNear(base.points, baseCloud.raster, m, fine, base.angleStep, base.angleStep, 1, 1);
    // q = m + shift + R (p - m) = centre + R (p - centre)  <=>  (I - R) centre = (I - R) m + shift.
    const double ca = std::cos(fine.angle), sa = std::sin(fine.angle);
    const cv::Matx22d iMinusR(1.0 - ca, -sa, sa, 1.0 - ca);
    const cv::Vec2d rhs = iMinusR * cv::Vec2d(m.x, m.y) + cv::Vec2d(fine.shift.x, fine.shift.y);
    const cv::Vec2d centre = iMinusR.inv() * rhs;
    out.push_back({wrapAngle(fine.angle), {centre[0], centre[1]}, fine.score});
  }
  return out;
}

namespace {

// The points' bounding box, half a pixel wider on every side.
cv::Rect2d extentOf(const std::vector<ShapePoint>& points) {
  float x0 = points[0].position.x, x1 = x0, y0 = points[0].position.y, y1 = y0;
  for (const auto& p : points) {
    x0 = std::min(x0, p.position.x), x1 = std::max(x1, p.position.x);
    y0 = std::min(y0, p.position.y), y1 = std::max(y1, p.position.y);
  }
  return {x0 - 0.5, y0 - 0.5, x1 - x0 + 1.0, y1 - y0 + 1.0};
}

// Mean over every `stride`-th point whose shifted place lies within `extent` of the best direction
// agreement within one pixel there; 0 where fewer than a third of the points stay within it (the
// shift is then no period of the model's own pattern).
double shiftedSimilarity(const std::vector<ShapePoint>& points, const PointRaster& raster,
                         const cv::Rect2d& extent, cv::Point2d shift, std::size_t stride) {
  const cv::Rect inside(1, 1, raster.directions.cols - 2, raster.directions.rows - 2);
  double sum = 0.0;
  std::size_t within = 0, all = 0;
  for (std::size_t i = 0; i < points.size(); i += stride, ++all) {
    const ShapePoint& p = points[i];
    const cv::Point2d q(p.position.x + shift.x, p.position.y + shift.y);
    if (!extent.contains(q)) continue;
    ++within;
    const cv::Point at(cvRound(q.x - raster.origin.x), cvRound(q.y - raster.origin.y));
    if (!inside.contains(at)) continue;
    double best = 0.0;
    for (int v = -1; v <= 1; ++v)
      for (int u = -1; u <= 1; ++u) {
        const cv::Vec2f d = raster.directions.at<cv::Vec2f>(at + cv::Point(u, v));
        best = std::max(best, double(d[0] * p.direction.x + d[1] * p.direction.y));
      }
    sum += best;
  }
  return 3 * within < all || within == 0 ? 0.0 : sum / static_cast<double>(within);
}

}  // namespace

std::vector<ModelPeriod> findSearchPeriods(const std::vector<ShapeLevel>& levels, int topReach,
                                           double minScore, int maxCount, double levelZeroShare) {
  if (levels.size() < 2 || levels.front().points.size() < 8 || levels.back().points.size() < 8)
    return {};
  const std::vector<ShapePoint>& points = levels.front().points;
  const double topPixel = std::ldexp(1.0, static_cast<int>(levels.size()) - 1);
  // A shift whose pose may land within topReach of the candidate's in x and y at some angle,
  // once both are rounded to the top level's pixels.
  const double longest = (topReach + 1) * std::numbers::sqrt2 * topPixel;
  const double shortest = topPixel;
  const Cloud cloud = cloudOf(points);
  const cv::Rect2d extent = extentOf(points);
  // The top level's own points, where the pattern may have been smoothed away.
  const std::vector<ShapePoint>& topPoints = levels.back().points;
  const Cloud topCloud = cloudOf(topPoints);
  const cv::Rect2d topExtent = extentOf(topPoints);
  const std::size_t stride = std::max<std::size_t>(1, points.size() / kSampledPoints);
  const int r = static_cast<int>(std::ceil(longest));
  const int side = 2 * r + 3;
  // Every shift scored with a sample first; with all points near the threshold (as the turns).
  cv::Mat full(side, side, CV_64F, cv::Scalar(-1.0));
  const auto fullAt = [&](int dx, int dy) {
    double& v = full.at<double>(dy + r + 1, dx + r + 1);
    if (v < 0.0) v = shiftedSimilarity(points, cloud.raster, extent, cv::Point2d(dx, dy), 1);
    return v;
  };
  const double levelZeroScore = levelZeroShare * minScore;
  std::vector<ModelPeriod> out;
  for (int dy = -r; dy <= r; ++dy)
    for (int dx = -r; dx <= r; ++dx) {
      const double length = std::hypot(dx, dy);
      if (length < shortest || length > longest) continue;
      if (shiftedSimilarity(points, cloud.raster, extent, cv::Point2d(dx, dy), stride) <
          levelZeroScore - kSampleMargin)
        continue;
      const double v = fullAt(dx, dy);
      if (v < levelZeroScore) continue;
      bool peak = true;
      for (int ey = -1; ey <= 1 && peak; ++ey)
        for (int ex = -1; ex <= 1 && peak; ++ex)
          if ((ex || ey) && fullAt(dx + ex, dy + ey) > v) peak = false;
      // A period: halfway to it the pattern does not repeat. Along a straight edge it does.
      if (!peak || fullAt(static_cast<int>(std::lround(dx / 2.0)),
                          static_cast<int>(std::lround(dy / 2.0))) >= 0.5 * v)
        continue;
      // Only a pattern the top level still sees makes its peaks compete there (a cloth's fine
      // weave, 2-3 px apart, is gone a level up; a dark stripe across it is not).
      if (shiftedSimilarity(topPoints, topCloud.raster, topExtent, cv::Point2d(dx, dy) / topPixel,
                            1) < minScore)
        continue;
      out.push_back({cv::Point2d(dx, dy), v});
    }
  std::sort(out.begin(), out.end(),
            [](const ModelPeriod& a, const ModelPeriod& b) { return a.score > b.score; });
  if (static_cast<int>(out.size()) > maxCount) out.resize(static_cast<std::size_t>(maxCount));
  return out;
}

std::vector<ModelPeriod> findTrackedPeriods(const std::vector<ShapeLevel>& levels) {
  std::vector<ModelPeriod> periods =
      findSearchPeriods(levels, shape_detail::kPeakReach, 0.7, 4, shape_detail::kTopFactor);
  // A shift's opposite is a period as well; only the points that stay within the model's extent
  // score it, and they are others (a slanted board's period scored 0.72 one way, 0.58 the other,
  // and the part lay the other way from its neighbour).
  const std::size_t found = periods.size();
  for (std::size_t i = 0; i < found; ++i) {
    const ModelPeriod opposite{-periods[i].shift, periods[i].score};
    const bool listed = std::any_of(periods.begin(), periods.end(), [&](const ModelPeriod& p) {
      return std::hypot(p.shift.x - opposite.shift.x, p.shift.y - opposite.shift.y) <= 1.5;
    });
    if (!listed) periods.push_back(opposite);
  }
  return periods;
}

Pose2D turnedBy(const Pose2D& pose, const ModelSymmetry& symmetry) {
  const double c = std::cos(symmetry.angle), s = std::sin(symmetry.angle);
  const cv::Point2d& m = symmetry.centre;
  const cv::Point2d turned(c * m.x + s * m.y, -s * m.x + c * m.y);
  // t' = t + s R(theta) (c - R(a) c)
  const cv::Point2d shift = pose.applyToVector(m - turned);
  return {pose.x + shift.x, pose.y + shift.y, wrapAngle(pose.angle + symmetry.angle), pose.scale};
}

}  // namespace facet
