#include "algorithms/shape/shape_similarity.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>

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

double scorePose(const cv::Mat& field, const PosedPoints& posed, cv::Point at, Polarity polarity,
                 double minScore, double greediness) {
  const int n = static_cast<int>(posed.offsets.size());
  const double invN = 1.0 / n;
  const double safe = minScore - 1.0, greedy = minScore;
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
      const double f = j1 * invN;
      const double bound = (1.0 - greediness) * (safe + f) + greediness * greedy * f;
      const double partial = (polarity == Polarity::IgnoreGlobal ? std::abs(sum) : sum) * invN;
      if (partial < bound) return -1.0;
    }
  }
  return (polarity == Polarity::IgnoreGlobal ? std::abs(sum) : sum) * invN;
}

double refinedScore(const cv::Mat& field, const ShapeModel& model, const Pose2D& pose,
                    Polarity polarity) {
  const double c = std::cos(pose.angle), s = std::sin(pose.angle);
  const Pose2D::Map toImage = pose.map();
  double sum = 0.0;
  for (const auto& mp : model.finePoints) {
    const cv::Point2d q = toImage(mp.position);
    const int x0 = static_cast<int>(std::floor(q.x)), y0 = static_cast<int>(std::floor(q.y));
    if (x0 < 0 || y0 < 0 || x0 + 1 >= field.cols || y0 + 1 >= field.rows) continue;
    const double fx = q.x - x0, fy = q.y - y0;
    const Direction* r0 = field.ptr<Direction>(y0) + x0;
    const Direction* r1 = field.ptr<Direction>(y0 + 1) + x0;
    double gx = 0.0, gy = 0.0;
    const double w[4] = {(1 - fx) * (1 - fy), fx * (1 - fy), (1 - fx) * fy, fx * fy};
    const Direction* d[4] = {r0, r0 + 1, r1, r1 + 1};
    for (int k = 0; k < 4; ++k) gx += w[k] * (*d[k])[0], gy += w[k] * (*d[k])[1];
    const double norm = std::hypot(gx, gy);
    if (norm < 1e-6) continue;
    const double dot = ((c * mp.direction.x + s * mp.direction.y) * gx +
                        (-s * mp.direction.x + c * mp.direction.y) * gy) /
                       norm;
    sum += polarity == Polarity::IgnoreLocal ? std::abs(dot) : dot;
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
