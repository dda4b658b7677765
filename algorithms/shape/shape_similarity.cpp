#include "algorithms/shape/shape_similarity.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <numbers>
#include <optional>

#include <opencv2/core/hal/intrin.hpp>

#include "algorithms/shape/image_gradients.hpp"

namespace facet::shape_detail {

PosedPoints posePoints(const std::vector<ShapePoint>& points, double angle, double scale) {
  const double c = std::cos(angle), s = std::sin(angle);
  PosedPoints out;
  // Sized once and written in place: the tracking down the pyramid poses hundreds of times.
  out.offsets.resize(points.size());
  out.directions.resize(points.size());
  cv::Point* offsets = out.offsets.data();
  cv::Point2f* directions = out.directions.data();
  for (std::size_t i = 0; i < points.size(); ++i) {
    const double x = points[i].position.x, y = points[i].position.y;
    offsets[i] = {cvRound(scale * (c * x + s * y)), cvRound(scale * (-s * x + c * y))};
    const double dx = points[i].direction.x, dy = points[i].direction.y;
    directions[i] = {static_cast<float>(c * dx + s * dy), static_cast<float>(-s * dx + c * dy)};
  }
  return out;
}

namespace {

// The most one point can add to a score, which the safe early termination assumes of every point
// not yet read. Not 1: an image direction's components are rounded to integers, so it is up to
// 127 + 0.5 sqrt(2) = 127.71 long against the 127 it is divided by; the deformation-tolerant
// score's rounded model direction (128 long) adds as much again. Bounding with 1 abandoned poses
// that would have scored up to that much above the bar: the local search then kept a worse pose
// beside the best (1.00018 for 1.00227, deformation 1 px).
constexpr double kMostPerPoint = (127.0 + 0.5 * std::numbers::sqrt2) / 127.0;
constexpr double kMostPerSpreadPoint = kMostPerPoint * (128.0 + 0.5 * std::numbers::sqrt2) / 128.0;

// The early termination's bound after a share f of the points: between every remaining point
// adding `most` (greediness 0) and each adding minScore (greediness 1).
double abandonBelow(double minScore, double greediness, double f, double most) {
  return (1.0 - greediness) * (minScore - most * (1.0 - f)) + greediness * minScore * f;
}

// The best dot product of a turned model direction (mx, my; 128 long) with the image directions in
// a window of `side` (<= 8) pixels a row, rows v0..v1, starting at column u0, with at least 8
// columns from u0 inside the field: a row's eight directions are one 16-byte load. Columns past
// the window meet a zero model direction and give 0, which never beats a pixel without a direction.
int bestDotInWindow(const cv::Mat& field, int u0, int v0, int v1, int side, int mx, int my,
                    bool local) {
  alignas(16) std::int16_t lanes[16] = {};
  for (int k = 0; k < side; ++k)
    lanes[2 * k] = static_cast<std::int16_t>(mx), lanes[2 * k + 1] = static_cast<std::int16_t>(my);
  const cv::v_int16x8 mLow = cv::v_load_aligned(lanes), mHigh = cv::v_load_aligned(lanes + 8);
  cv::v_int32x4 best = cv::v_setzero_s32();
  for (int v = v0; v <= v1; ++v) {
    const auto* row = reinterpret_cast<const schar*>(field.ptr<Direction>(v) + u0);
    cv::v_int16x8 low, high;
    cv::v_expand(cv::v_load(row), low, high);
    const auto magnitude = [local](cv::v_int32x4 dots) {
      return local ? cv::v_reinterpret_as_s32(cv::v_abs(dots)) : dots;
    };
    best = cv::v_max(best, magnitude(cv::v_dotprod(low, mLow)));
    if (side > 4) best = cv::v_max(best, magnitude(cv::v_dotprod(high, mHigh)));
  }
  return cv::v_reduce_max(best);
}

// scorePose with each point's best direction within `spread`, apart from the rigid loop, which is
// most of the tracking down the pyramid. Integer dot products (image directions 127 long, the
// model's 128); reads (2 spread + 1)^2 pixels a point, a row at a time where it can.
double scoreSpreadPose(const cv::Mat& field, const PosedPoints& posed, cv::Point at,
                       Polarity polarity, double minScore, double greediness, int spread) {
  const int n = static_cast<int>(posed.offsets.size());
  const double invN = 1.0 / n, unit = 1.0 / (127.0 * 128.0);
  const bool local = polarity == Polarity::IgnoreLocal;
  const int w = field.cols, h = field.rows;
  long sum = 0;
  for (int j = 0; j < n; ++j) {
    const int x = at.x + posed.offsets[j].x, y = at.y + posed.offsets[j].y;
    if (x < 0 || y < 0 || x >= w || y >= h) continue;
    // cvRound: one conversion instruction (std::lround is a library call, 8% of a deformable
    // search); the two differ only on exact halves, by one unit of 128 in one component.
    const int mx = cvRound(posed.directions[j].x * 128.0f);
    const int my = cvRound(posed.directions[j].y * 128.0f);
    const int u0 = std::max(x - spread, 0), u1 = std::min(x + spread, w - 1);
    const int v0 = std::max(y - spread, 0), v1 = std::min(y + spread, h - 1);
    int best = 0;  // a pixel without a direction
    if (u0 + 8 <= w && u1 - u0 < 8) {
      best = bestDotInWindow(field, u0, v0, v1, u1 - u0 + 1, mx, my, local);
    } else {
      for (int v = v0; v <= v1; ++v) {
        const Direction* row = field.ptr<Direction>(v);
        for (int u = u0; u <= u1; ++u) {
          const int dot = row[u][0] * mx + row[u][1] * my;
          best = std::max(best, local ? std::abs(dot) : dot);
        }
      }
    }
    sum += best;
    if ((j & 7) == 7 && minScore > 0.0) {
      const double f = (j + 1) * invN;
      if (sum * unit * invN < abandonBelow(minScore, greediness, f, kMostPerSpreadPoint))
        return -1.0;
    }
  }
  return sum * unit * invN;
}

}  // namespace

double scorePose(const cv::Mat& field, const PosedPoints& posed, cv::Point at, Polarity polarity,
                 double minScore, double greediness, int spread) {
  if (spread > 0) return scoreSpreadPose(field, posed, at, polarity, minScore, greediness, spread);
  const int n = static_cast<int>(posed.offsets.size());
  const double invN = 1.0 / n;
  double sum = 0.0;
  const auto w = static_cast<unsigned>(field.cols), h = static_cast<unsigned>(field.rows);
  // Plain pointers and blocks of eight points between the checks: the loop is most of the
  // tracking down the pyramid, and its loads of the field's and the points' headers are not.
  const uchar* data = field.data;
  const std::size_t rowStep = field.step[0];
  const cv::Point* offsets = posed.offsets.data();
  const cv::Point2f* directions = posed.directions.data();
  const bool local = polarity == Polarity::IgnoreLocal;
  const bool check = minScore > 0.0;
  for (int j0 = 0; j0 < n; j0 += 8) {
    const int j1 = std::min(j0 + 8, n);
    for (int j = j0; j < j1; ++j) {
      // Unsigned: a negative coordinate is out of range as well.
      const auto x = static_cast<unsigned>(at.x + offsets[j].x);
      const auto y = static_cast<unsigned>(at.y + offsets[j].y);
      if (x < w && y < h) {
        const Direction g = reinterpret_cast<const Direction*>(data + y * rowStep)[x];
        const double dot = (g[0] * directions[j].x + g[1] * directions[j].y) * (1.0 / 127);
        sum += local ? std::abs(dot) : dot;
      }
    }
    if (j1 - j0 == 8 && check) {
      const double bound = abandonBelow(minScore, greediness, j1 * invN, kMostPerPoint);
      const double partial = (polarity == Polarity::IgnoreGlobal ? std::abs(sum) : sum) * invN;
      if (partial < bound) return -1.0;
    }
  }
  return (polarity == Polarity::IgnoreGlobal ? std::abs(sum) : sum) * invN;
}

double bestScoreAround(const cv::Mat& field, const PosedPoints& posed, cv::Point at,
                       Polarity polarity, int spread) {
  double best = scorePose(field, posed, at, polarity, 0.0, 0.0, spread);
  for (int dy = -1; dy <= 1; ++dy)
    for (int dx = -1; dx <= 1; ++dx)
      if (dx || dy)
        best = std::max(
            best, scorePose(field, posed, at + cv::Point(dx, dy), polarity, 0.0, 0.0, spread));
  return best;
}

double refinedScore(const cv::Mat& field, const ShapeModel& model, const Pose2D& pose,
                    Polarity polarity, int spread) {
  const double c = std::cos(pose.angle), s = std::sin(pose.angle);
  const Pose2D::Map toImage = pose.map();
  const bool local = polarity == Polarity::IgnoreLocal;
  // The normalised, bilinearly interpolated image direction at q against the turned model
  // direction (tx, ty); nullopt outside the image or where no direction is.
  auto similarity = [&](cv::Point2d q, double tx, double ty) -> std::optional<double> {
    const int x0 = static_cast<int>(std::floor(q.x)), y0 = static_cast<int>(std::floor(q.y));
    if (x0 < 0 || y0 < 0 || x0 + 1 >= field.cols || y0 + 1 >= field.rows) return std::nullopt;
    const double fx = q.x - x0, fy = q.y - y0;
    const Direction* r0 = field.ptr<Direction>(y0) + x0;
    const Direction* r1 = field.ptr<Direction>(y0 + 1) + x0;
    double gx = 0.0, gy = 0.0;
    const double w[4] = {(1 - fx) * (1 - fy), fx * (1 - fy), (1 - fx) * fy, fx * fy};
    const Direction* d[4] = {r0, r0 + 1, r1, r1 + 1};
    for (int k = 0; k < 4; ++k) gx += w[k] * (*d[k])[0], gy += w[k] * (*d[k])[1];
    const double norm = std::hypot(gx, gy);
    if (norm < 1e-6) return std::nullopt;
    const double dot = (tx * gx + ty * gy) / norm;
    return local ? std::abs(dot) : dot;
  };
  double sum = 0.0;
  for (const auto& mp : model.finePoints) {
    const cv::Point2d q = toImage(mp.position);
    const double tx = c * mp.direction.x + s * mp.direction.y;
    const double ty = -s * mp.direction.x + c * mp.direction.y;
    if (spread == 0) {
      sum += similarity(q, tx, ty).value_or(0.0);
      continue;
    }
    // As on the pyramid: a point outside the image scores 0, one without a direction near it 0.
    if (q.x < 0 || q.y < 0 || q.x + 1 >= field.cols || q.y + 1 >= field.rows) continue;
    double best = 0.0;
    for (int v = -spread; v <= spread; ++v)
      for (int u = -spread; u <= spread; ++u)
        best = std::max(best, similarity(q + cv::Point2d(u, v), tx, ty).value_or(0.0));
    sum += best;
  }
  const double n = static_cast<double>(model.finePoints.size());
  return (polarity == Polarity::IgnoreGlobal ? std::abs(sum) : sum) / n;
}

std::vector<std::uint8_t> pointsNearGradients(const cv::Mat& field, const ShapeModel& model,
                                              const Pose2D& pose) {
  std::vector<std::uint8_t> near(model.finePoints.size(), 0);
  const Pose2D::Map toImage = pose.map();
  for (std::size_t i = 0; i < near.size(); ++i) {
    const cv::Point2d q = toImage(model.finePoints[i].position);
    const int x = cvRound(q.x), y = cvRound(q.y);
    for (int v = std::max(y - 1, 0); v <= std::min(y + 1, field.rows - 1) && !near[i]; ++v) {
      const Direction* row = field.ptr<Direction>(v);
      for (int u = std::max(x - 1, 0); u <= std::min(x + 1, field.cols - 1); ++u)
        if (row[u][0] != 0 || row[u][1] != 0) near[i] = 1;
    }
  }
  return near;
}

}  // namespace facet::shape_detail
