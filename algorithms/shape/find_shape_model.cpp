#include "algorithms/shape/find_shape_model.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <thread>

#include <Eigen/Dense>
#include <opencv2/imgproc.hpp>

#include "algorithms/edges/subpixel_edges.hpp"
#include "algorithms/shape/image_gradients.hpp"

namespace facet {
namespace {

using shape_detail::sobelGradients;
using shape_detail::toGreyFloat;

constexpr double kTwoPi = 2.0 * std::numbers::pi;
constexpr int kBins = 32;               // quantised orientations of the top-level response maps
constexpr int kMaxTopPoints = 250;      // 16-bit sums: 250 * 127 < 32767
constexpr double kTopFactor = 0.7;      // top-level threshold, relative to minScore
constexpr double kMiddleFactor = 0.85;  // threshold on levels between top and 0

// ---------------------------------------------------------------------------------------------
// Search space

struct Interval {
  double start = 0.0;
  double extent = 0.0;
  bool full = false;  // angle: the whole circle
};

std::vector<double> angleSamples(const Interval& range, double step) {
  std::vector<double> out;
  if (range.full) {
    const int n = std::max(1, static_cast<int>(std::ceil(kTwoPi / step)));
    for (int k = 0; k < n; ++k) out.push_back(wrapAngle(k * kTwoPi / n));
  } else {
    const int n = range.extent > 0.0 ? static_cast<int>(std::ceil(range.extent / step)) + 1 : 1;
    for (int k = 0; k < n; ++k)
      out.push_back(n == 1 ? range.start + range.extent / 2
                           : range.start + k * range.extent / (n - 1));
  }
  return out;
}

std::vector<double> scaleSamples(double lo, double hi, double step) {
  if (hi <= lo || step <= 0.0) return {lo};
  const int n = static_cast<int>(std::ceil((hi - lo) / step)) + 1;
  std::vector<double> out;
  for (int k = 0; k < n; ++k) out.push_back(lo + k * (hi - lo) / (n - 1));
  return out;
}

// The model's trained angle range intersected with the requested one; nullopt when they miss.
std::optional<Interval> angleRange(const ShapeModel& model, const FindParams& params) {
  const bool modelFull = model.angleExtent >= kTwoPi - 1e-9;
  const bool paramsFull = params.angleExtent >= kTwoPi - 1e-9;
  if (modelFull && paramsFull) return Interval{0.0, kTwoPi, true};
  if (modelFull) return Interval{params.angleStart, params.angleExtent, false};
  if (paramsFull) return Interval{model.angleStart, model.angleExtent, false};
  // Shift the requested interval by whole turns to where it meets the model's most.
  double best = -1.0, bestStart = 0.0;
  for (int k = -2; k <= 2; ++k) {
    const double s = params.angleStart + k * kTwoPi;
    const double lo = std::max(s, model.angleStart);
    const double hi = std::min(s + params.angleExtent, model.angleStart + model.angleExtent);
    if (hi - lo > best) best = hi - lo, bestStart = lo;
  }
  if (best < 0.0) return std::nullopt;
  return Interval{bestStart, best, false};
}

// ---------------------------------------------------------------------------------------------
// Image side: normalised gradient directions per pyramid level

// Unit gradient directions (CV_32FC2); zero where the gradient is weaker than minContrast, so
// that noise contributes nothing to the score.
cv::Mat directionField(const cv::Mat& grey, double minContrast) {
  cv::Mat gx, gy;
  sobelGradients(grey, gx, gy);
  cv::Mat field(grey.size(), CV_32FC2);
  const float min2 = static_cast<float>(std::max(minContrast * minContrast, 1e-6));
  for (int y = 0; y < grey.rows; ++y) {
    const float* px = gx.ptr<float>(y);
    const float* py = gy.ptr<float>(y);
    auto* out = field.ptr<cv::Vec2f>(y);
    for (int x = 0; x < grey.cols; ++x) {
      const float m2 = px[x] * px[x] + py[x] * py[x];
      const float inv = m2 >= min2 ? 1.0f / std::sqrt(m2) : 0.0f;
      out[x] = {px[x] * inv, py[x] * inv};
    }
  }
  return field;
}

// ---------------------------------------------------------------------------------------------
// Model side: points at a pose

struct PosedPoints {
  std::vector<cv::Point> offsets;       // rounded s R(a) p, pixels of the level
  std::vector<cv::Point2f> directions;  // R(a) d
};

PosedPoints posePoints(const std::vector<ShapePoint>& points, double angle, double scale) {
  const double c = std::cos(angle), s = std::sin(angle);
  PosedPoints out;
  out.offsets.reserve(points.size());
  out.directions.reserve(points.size());
  for (const auto& p : points) {
    const double x = p.position.x, y = p.position.y;
    out.offsets.emplace_back(cvRound(scale * (c * x + s * y)), cvRound(scale * (-s * x + c * y)));
    const double dx = p.direction.x, dy = p.direction.y;
    out.directions.emplace_back(static_cast<float>(c * dx + s * dy),
                                static_cast<float>(-s * dx + c * dy));
  }
  return out;
}

// Steger's similarity at an integer position, with early termination: after j of n points the
// pose is abandoned when the partial mean falls below a bound between the safe one (every
// remaining point matches perfectly, greediness 0) and the greedy one (the remaining points match
// at exactly minScore, greediness 1). Returns the score, or a value below minScore if abandoned.
double scorePose(const cv::Mat& field, const PosedPoints& posed, cv::Point at, Polarity polarity,
                 double minScore, double greediness) {
  const int n = static_cast<int>(posed.offsets.size());
  const double invN = 1.0 / n;
  const double safe = minScore - 1.0, greedy = minScore;
  double sum = 0.0;
  const int w = field.cols, h = field.rows;
  for (int j = 0; j < n; ++j) {
    const int x = at.x + posed.offsets[j].x, y = at.y + posed.offsets[j].y;
    if (x >= 0 && y >= 0 && x < w && y < h) {
      const cv::Vec2f g = field.ptr<cv::Vec2f>(y)[x];
      const double dot = g[0] * posed.directions[j].x + g[1] * posed.directions[j].y;
      sum += polarity == Polarity::IgnoreLocal ? std::abs(dot) : dot;
    }
    if ((j & 7) == 7 && minScore > 0.0) {
      const double f = (j + 1) * invN;
      const double bound = (1.0 - greediness) * (safe + f) + greediness * greedy * f;
      const double partial = (polarity == Polarity::IgnoreGlobal ? std::abs(sum) : sum) * invN;
      if (partial < bound) return -1.0;
    }
  }
  return (polarity == Polarity::IgnoreGlobal ? std::abs(sum) : sum) * invN;
}

// ---------------------------------------------------------------------------------------------
// Top level: exhaustive search over (x, y, angle, scale) with quantised-orientation response
// maps. Map b holds 127 cos(theta - theta_b) for every pixel, so the score of a template is a sum
// of shifted map rows: one vectorisable 8-bit add per point and row.

struct TopTemplate {
  double angle = 0.0;
  double scale = 1.0;
  std::vector<int> offsets;  // into a padded map plane
  std::vector<int> bins;
};

struct Candidate {
  double x = 0.0, y = 0.0;  // position on the current level, pixels
  double angle = 0.0;
  double scale = 1.0;
  double score = 0.0;
};

std::vector<Candidate> searchTopLevel(const cv::Mat& field,
                                      const std::vector<ShapePoint>& modelPoints,
                                      const std::vector<double>& angles,
                                      const std::vector<double>& scales, const FindParams& params,
                                      int maxCandidates) {
  std::vector<ShapePoint> points = modelPoints;
  if (points.size() > kMaxTopPoints) {
    std::vector<ShapePoint> kept;
    const double stride = static_cast<double>(points.size()) / kMaxTopPoints;
    for (int i = 0; i < kMaxTopPoints; ++i)
      kept.push_back(points[static_cast<std::size_t>(i * stride)]);
    points.swap(kept);
  }
  double radius = 0.0;
  for (const auto& p : points)
    radius = std::max(radius, std::hypot(double(p.position.x), double(p.position.y)));
  const int border = static_cast<int>(std::ceil(radius * scales.back())) + 2;
  const int w = field.cols, h = field.rows;
  const int stride = w + 2 * border;
  const std::size_t plane = static_cast<std::size_t>(stride) * (h + 2 * border);
  const bool local = params.polarity == Polarity::IgnoreLocal;

  std::vector<std::int8_t> maps(plane * kBins, 0);
  std::array<float, kBins> cosB{}, sinB{};
  for (int b = 0; b < kBins; ++b) {
    cosB[b] = static_cast<float>(std::cos(b * kTwoPi / kBins));
    sinB[b] = static_cast<float>(std::sin(b * kTwoPi / kBins));
  }
  for (int y = 0; y < h; ++y) {
    const auto* row = field.ptr<cv::Vec2f>(y);
    const std::size_t base = static_cast<std::size_t>(y + border) * stride + border;
    for (int x = 0; x < w; ++x) {
      if (row[x][0] == 0.0f && row[x][1] == 0.0f) continue;
      for (int b = 0; b < kBins; ++b) {
        float v = 127.0f * (row[x][0] * cosB[b] + row[x][1] * sinB[b]);
        if (local) v = std::abs(v);
        maps[b * plane + base + x] = static_cast<std::int8_t>(std::lround(v));
      }
    }
  }

  std::vector<TopTemplate> templates;
  for (double s : scales) {
    for (double a : angles) {
      TopTemplate t{a, s, {}, {}};
      const PosedPoints posed = posePoints(points, a, s);
      for (std::size_t i = 0; i < points.size(); ++i) {
        t.offsets.push_back(posed.offsets[i].y * stride + posed.offsets[i].x);
        const double theta = std::atan2(posed.directions[i].y, posed.directions[i].x);
        t.bins.push_back(((static_cast<int>(std::lround(theta / kTwoPi * kBins)) % kBins) + kBins) %
                         kBins);
      }
      templates.push_back(std::move(t));
    }
  }

  // Best template per pixel.
  std::vector<std::int16_t> best(static_cast<std::size_t>(w) * h, 0);
  std::vector<std::int32_t> bestTemplate(best.size(), -1);
  const bool global = params.polarity == Polarity::IgnoreGlobal;
  auto work = [&](int y0, int y1) {
    std::vector<std::int16_t> acc(w);
    for (int y = y0; y < y1; ++y) {
      const std::size_t rowBase = static_cast<std::size_t>(y + border) * stride + border;
      std::int16_t* bestRow = best.data() + static_cast<std::size_t>(y) * w;
      std::int32_t* bestIdx = bestTemplate.data() + static_cast<std::size_t>(y) * w;
      for (std::size_t t = 0; t < templates.size(); ++t) {
        const TopTemplate& tpl = templates[t];
        std::fill(acc.begin(), acc.end(), 0);
        std::int16_t* a = acc.data();
        for (std::size_t i = 0; i < tpl.offsets.size(); ++i) {
          const std::int8_t* src = maps.data() + tpl.bins[i] * plane + rowBase + tpl.offsets[i];
          for (int x = 0; x < w; ++x) a[x] = static_cast<std::int16_t>(a[x] + src[x]);
        }
        for (int x = 0; x < w; ++x) {
          const std::int16_t v = global ? static_cast<std::int16_t>(std::abs(a[x])) : a[x];
          if (v > bestRow[x]) bestRow[x] = v, bestIdx[x] = static_cast<std::int32_t>(t);
        }
      }
    }
  };
  const int threads = std::clamp(params.threads, 1, 8);
  if (threads == 1 || h < 2 * threads) {
    work(0, h);
  } else {
    std::vector<std::thread> pool;
    for (int k = 1; k < threads; ++k)
      pool.emplace_back(work, h * k / threads, h * (k + 1) / threads);
    work(0, h / threads);
    for (auto& t : pool) t.join();
  }

  // Local maxima above the threshold.
  const double norm = 127.0 * static_cast<double>(points.size());
  const auto threshold =
      static_cast<std::int16_t>(std::min(32767.0, kTopFactor * params.minScore * norm));
  std::vector<Candidate> candidates;
  constexpr int r = 2;
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const std::int16_t v = best[static_cast<std::size_t>(y) * w + x];
      if (v < threshold || v <= 0) continue;
      bool isMax = true;
      for (int dy = -r; dy <= r && isMax; ++dy)
        for (int dx = -r; dx <= r; ++dx) {
          const int xx = x + dx, yy = y + dy;
          if ((dx == 0 && dy == 0) || xx < 0 || yy < 0 || xx >= w || yy >= h) continue;
          const std::int16_t u = best[static_cast<std::size_t>(yy) * w + xx];
          // Strict on one side so that a plateau yields one maximum.
          if (u > v || (u == v && (dy < 0 || (dy == 0 && dx < 0)))) {
            isMax = false;
            break;
          }
        }
      if (!isMax) continue;
      const TopTemplate& tpl = templates[bestTemplate[static_cast<std::size_t>(y) * w + x]];
      candidates.push_back({double(x), double(y), tpl.angle, tpl.scale, v / norm});
    }
  }
  std::sort(candidates.begin(), candidates.end(),
            [](const Candidate& a, const Candidate& b) { return a.score > b.score; });
  if (static_cast<int>(candidates.size()) > maxCandidates) candidates.resize(maxCandidates);
  return candidates;
}

// ---------------------------------------------------------------------------------------------
// Tracking one candidate down one level: a local search around the parent's pose.

struct LevelSearch {
  const cv::Mat* field = nullptr;
  const ShapeLevel* level = nullptr;
  Interval angles;
  double scaleMin = 1.0, scaleMax = 1.0;
  Polarity polarity = Polarity::Use;
  double minScore = 0.0;
  double greediness = 0.0;
};

double clampAngle(const Interval& range, double a) {
  if (range.full) return wrapAngle(a);
  return std::clamp(a, range.start, range.start + range.extent);
}

// Best pose in a (2r+1)^2 x 3 x 3 neighbourhood of `c`, climbing while the best lies on the border.
Candidate refineOnLevel(const LevelSearch& s, Candidate c, int radius) {
  const double aStep = s.level->angleStep;
  const double sStep = s.scaleMax > s.scaleMin ? s.level->scaleStep : 0.0;
  Candidate best = c;
  best.score = -1.0;
  for (int climb = 0; climb < 6; ++climb) {
    Candidate centre = climb == 0 ? c : best;
    bool onBorder = false;
    const int ns = sStep > 0.0 ? 1 : 0;
    for (int k = -1; k <= 1; ++k) {
      const double a = clampAngle(s.angles, centre.angle + k * aStep);
      for (int m = -ns; m <= ns; ++m) {
        const double sc = std::clamp(centre.scale + m * sStep, s.scaleMin, s.scaleMax);
        const PosedPoints posed = posePoints(s.level->points, a, sc);
        for (int dy = -radius; dy <= radius; ++dy)
          for (int dx = -radius; dx <= radius; ++dx) {
            const cv::Point at(cvRound(centre.x) + dx, cvRound(centre.y) + dy);
            const double score = scorePose(*s.field, posed, at, s.polarity,
                                           std::max(s.minScore, best.score), s.greediness);
            if (score > best.score) {
              best = {double(at.x), double(at.y), a, sc, score};
              onBorder = std::abs(dx) == radius || std::abs(dy) == radius ||
                         (k != 0 && aStep > 0.0) || m != 0;
            }
          }
      }
    }
    if (!onBorder || best.score < s.minScore) break;
    radius = 1;
  }
  return best;
}

// Score-parabola interpolation around the level-0 maximum in x, y, angle and scale.
Candidate interpolate(const LevelSearch& s, Candidate c) {
  auto at = [&](double dx, double dy, double da, double ds) {
    const PosedPoints posed = posePoints(s.level->points, c.angle + da, c.scale + ds);
    return scorePose(*s.field, posed, cv::Point(cvRound(c.x + dx), cvRound(c.y + dy)), s.polarity,
                     0.0, 0.0);
  };
  auto vertex = [](double m, double z, double p) {
    const double d = m - 2.0 * z + p;
    return d < 0.0 ? std::clamp(0.5 * (m - p) / d, -0.5, 0.5) : 0.0;
  };
  const double z = at(0, 0, 0, 0);
  const double aStep = s.level->angleStep;
  Candidate out = c;
  out.x += vertex(at(-1, 0, 0, 0), z, at(1, 0, 0, 0));
  out.y += vertex(at(0, -1, 0, 0), z, at(0, 1, 0, 0));
  out.angle += aStep * vertex(at(0, 0, -aStep, 0), z, at(0, 0, aStep, 0));
  if (s.scaleMax > s.scaleMin) {
    const double sStep = s.level->scaleStep;
    out.scale += sStep * vertex(at(0, 0, 0, -sStep), z, at(0, 0, 0, sStep));
  }
  return out;
}

// ---------------------------------------------------------------------------------------------
// Least squares: ICP of the model's subpixel points against the image's Facet-model subpixel
// edges, minimising point-to-line distances along the image edge normals.

struct Box {
  double x0, y0, x1, y1;  // model coordinates
};

Box modelBox(const ShapeModel& model) {
  Box b{1e30, 1e30, -1e30, -1e30};
  for (const auto& p : model.finePoints) {
    b.x0 = std::min(b.x0, double(p.position.x)), b.x1 = std::max(b.x1, double(p.position.x));
    b.y0 = std::min(b.y0, double(p.position.y)), b.y1 = std::max(b.y1, double(p.position.y));
  }
  return b;
}

cv::RotatedRect placedBox(const Box& b, const Pose2D& pose) {
  const cv::Point2d centre = pose.apply({(b.x0 + b.x1) / 2, (b.y0 + b.y1) / 2});
  // cv::RotatedRect turns clockwise on screen; our angles turn counter-clockwise.
  return {cv::Point2f(static_cast<float>(centre.x), static_cast<float>(centre.y)),
          cv::Size2f(static_cast<float>(pose.scale * (b.x1 - b.x0 + 1)),
                     static_cast<float>(pose.scale * (b.y1 - b.y0 + 1))),
          static_cast<float>(-degrees(pose.angle))};
}

struct Refined {
  Pose2D pose;
  double residual = 0.0;
  bool ok = false;
};

Refined refineLeastSquares(const cv::Mat& image, const ShapeModel& model, const Box& box,
                           Pose2D pose, Polarity polarity, bool withScale) {
  Refined result{pose, 0.0, false};
  const cv::Rect roi = (placedBox(box, pose).boundingRect() + cv::Size(8, 8) - cv::Point(4, 4)) &
                       cv::Rect(0, 0, image.cols, image.rows);
  if (roi.width < 3 || roi.height < 3) return result;
  EdgeParams edgeParams;
  edgeParams.roi = roi;
  edgeParams.low = model.minContrast;
  edgeParams.high = std::max(2.0 * model.minContrast, 0.5 * model.contrastHigh);
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
  constexpr double kHuber = 0.25;  // pixels: beyond this, residuals are down-weighted
  double sign = 1.0;               // global polarity, decided on the first pass
  const int unknowns = withScale ? 4 : 3;
  for (int iteration = 0; iteration < 12; ++iteration) {
    const int radius = iteration < 2 ? 3 - iteration : 1;
    const double c = std::cos(pose.angle), s = std::sin(pose.angle);
    Eigen::Matrix4d H = Eigen::Matrix4d::Zero();
    Eigen::Vector4d g = Eigen::Vector4d::Zero();
    double sumSq = 0.0, polaritySum = 0.0;
    int used = 0;
    for (const auto& mp : model.finePoints) {
      const double px = mp.position.x, py = mp.position.y;
      const cv::Point2d q = pose.apply({px, py});
      const double dx = c * mp.direction.x + s * mp.direction.y;
      const double dy = -s * mp.direction.x + c * mp.direction.y;
      const int cx = cvRound(q.x) - roi.x, cy = cvRound(q.y) - roi.y;
      int bestIdx = -1;
      double bestD2 = 1e30, bestDot = 0.0;
      for (int v = cy - radius; v <= cy + radius; ++v) {
        if (v < 0 || v >= roi.height) continue;
        const int* row = cell.ptr<int>(v);
        for (int u = cx - radius; u <= cx + radius; ++u) {
          if (u < 0 || u >= roi.width || row[u] < 0) continue;
          const EdgePoint& e = edges.points[row[u]];
          const double dot = e.normal.x * dx + e.normal.y * dy;
          const double agree = polarity == Polarity::IgnoreLocal    ? std::abs(dot)
                               : polarity == Polarity::IgnoreGlobal ? sign * dot
                                                                    : dot;
          if (agree < kMinCos &&
              !(iteration == 0 && polarity == Polarity::IgnoreGlobal && std::abs(dot) >= kMinCos))
            continue;
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
      Eigen::Vector4d J(e.normal.x, e.normal.y, pose.scale * (e.normal.x * rpy - e.normal.y * rpx),
                        e.normal.x * rpx + e.normal.y * rpy);
      const double w = std::abs(r) <= kHuber ? 1.0 : kHuber / std::abs(r);
      H += w * J * J.transpose();
      g += w * r * J;
      sumSq += r * r;
      ++used;
    }
    if (iteration == 0 && polarity == Polarity::IgnoreGlobal) sign = polaritySum < 0 ? -1.0 : 1.0;
    if (used < 6) return result;
    Eigen::VectorXd delta = H.topLeftCorner(unknowns, unknowns).ldlt().solve(-g.head(unknowns));
    if (!delta.allFinite()) return result;
    pose.x += delta[0];
    pose.y += delta[1];
    pose.angle += delta[2];
    if (withScale) pose.scale += delta[3];
    result = {pose, std::sqrt(sumSq / used), true};
    if (std::hypot(delta[0], delta[1]) < 1e-4 && std::abs(delta[2]) < 1e-6) break;
  }
  result.pose.angle = wrapAngle(result.pose.angle);
  return result;
}

double overlap(const cv::RotatedRect& a, const cv::RotatedRect& b) {
  std::vector<cv::Point2f> region;
  if (cv::rotatedRectangleIntersection(a, b, region) == cv::INTERSECT_NONE || region.size() < 3)
    return 0.0;
  std::vector<cv::Point2f> hull;
  cv::convexHull(region, hull);
  const double smaller = std::min(a.size.area(), b.size.area());
  return smaller > 0.0 ? cv::contourArea(hull) / smaller : 0.0;
}

void checkParams(const ShapeModel& model, const FindParams& p) {
  if (model.empty()) throw std::invalid_argument("findShapeModel: the model is empty");
  if (!(p.minScore > 0.0 && p.minScore <= 1.0))
    throw std::invalid_argument("findShapeModel: minScore must lie in (0, 1]");
  if (p.numMatches < 0) throw std::invalid_argument("findShapeModel: numMatches must be >= 0");
  if (!(p.maxOverlap >= 0.0 && p.maxOverlap <= 1.0))
    throw std::invalid_argument("findShapeModel: maxOverlap must lie in [0, 1]");
  if (!(p.greediness >= 0.0 && p.greediness <= 1.0))
    throw std::invalid_argument("findShapeModel: greediness must lie in [0, 1]");
  if (!(p.angleExtent >= 0.0))
    throw std::invalid_argument("findShapeModel: angleExtent must be >= 0");
  if (p.scaleMin < 0.0 || p.scaleMax < 0.0 || (p.scaleMax > 0.0 && p.scaleMin > p.scaleMax))
    throw std::invalid_argument("findShapeModel: the scale range must satisfy 0 < min <= max");
  if (p.numLevels < 0) throw std::invalid_argument("findShapeModel: numLevels must be >= 0");
}

}  // namespace

std::vector<ShapeMatch> findShapeModel(const cv::Mat& image, const ShapeModel& model,
                                       const FindParams& params) {
  checkParams(model, params);
  if (image.empty()) return {};
  if (image.channels() != 1 || (image.depth() != CV_8U && image.depth() != CV_16U))
    throw std::invalid_argument("findShapeModel: expected an 8-bit or 16-bit single-channel image");

  const std::optional<Interval> angles = angleRange(model, params);
  const double scaleMin = std::max(model.scaleMin, params.scaleMin > 0.0 ? params.scaleMin : 0.0);
  const double scaleMax = std::min(model.scaleMax, params.scaleMax > 0.0 ? params.scaleMax : 1e9);
  if (!angles || scaleMin > scaleMax) return {};

  // Pyramid: as many levels as the model has and the image can hold.
  int levels =
      params.numLevels > 0 ? std::min(params.numLevels, model.numLevels()) : model.numLevels();
  while (levels > 1 && (std::min(image.cols, image.rows) >> (levels - 1)) < 8) --levels;
  std::vector<cv::Mat> fields(levels);
  {
    cv::Mat grey = toGreyFloat(image);
    for (int l = 0; l < levels; ++l) {
      if (l > 0) cv::pyrDown(grey, grey);
      fields[l] = directionField(grey, model.minContrast);
    }
  }

  const int top = levels - 1;
  const ShapeLevel& topLevel = model.levels[top];
  const int maxCandidates = params.numMatches == 0 ? 400 : 20 + 10 * params.numMatches;
  std::vector<Candidate> candidates =
      searchTopLevel(fields[top], topLevel.points, angleSamples(*angles, topLevel.angleStep),
                     scaleSamples(scaleMin, scaleMax, topLevel.scaleStep), params, maxCandidates);

  LevelSearch search;
  search.angles = *angles;
  search.scaleMin = scaleMin;
  search.scaleMax = scaleMax;
  search.polarity = params.polarity;
  search.greediness = params.greediness;
  for (int l = top - 1; l >= 0; --l) {
    search.field = &fields[l];
    search.level = &model.levels[l];
    search.minScore = params.minScore * (l == 0 ? 1.0 : kMiddleFactor);
    std::vector<Candidate> next;
    for (Candidate c : candidates) {
      c.x *= 2.0;
      c.y *= 2.0;
      const Candidate r = refineOnLevel(search, c, l == top - 1 ? 2 : 1);
      if (r.score >= search.minScore) next.push_back(r);
    }
    candidates.swap(next);
  }
  if (top == 0) {
    std::erase_if(candidates, [&](const Candidate& c) { return c.score < params.minScore; });
  }
  std::sort(candidates.begin(), candidates.end(),
            [](const Candidate& a, const Candidate& b) { return a.score > b.score; });

  // Non-maximum suppression by overlap of the placed model boxes.
  const Box box = modelBox(model);
  std::vector<Candidate> kept;
  std::vector<cv::RotatedRect> keptBoxes;
  for (const Candidate& c : candidates) {
    const cv::RotatedRect r = placedBox(box, {c.x, c.y, c.angle, c.scale});
    bool clash = false;
    for (const auto& k : keptBoxes) clash = clash || overlap(r, k) > params.maxOverlap;
    if (clash) continue;
    kept.push_back(c);
    keptBoxes.push_back(r);
    if (params.numMatches > 0 && static_cast<int>(kept.size()) >= params.numMatches) break;
  }

  search.field = &fields[0];
  search.level = &model.levels[0];
  std::vector<ShapeMatch> matches;
  for (Candidate c : kept) {
    ShapeMatch m;
    if (params.subpixel != SubpixelMode::None) c = interpolate(search, c);
    Pose2D pose{c.x, c.y, c.angle, c.scale};
    if (params.subpixel == SubpixelMode::LeastSquares) {
      const Refined r =
          refineLeastSquares(image, model, box, pose, params.polarity, scaleMax > scaleMin);
      // A refinement that wanders off by more than the search's own uncertainty has locked onto
      // something else.
      if (r.ok && std::hypot(r.pose.x - pose.x, r.pose.y - pose.y) < 3.0) {
        pose = r.pose;
        m.residual = r.residual;
      }
    }
    m.x = pose.x;
    m.y = pose.y;
    m.angle = wrapAngle(pose.angle);
    m.scale = pose.scale;
    m.score = c.score;
    m.contour.reserve(model.finePoints.size());
    for (const auto& p : model.finePoints) m.contour.push_back(pose.apply(p.position));
    matches.push_back(std::move(m));
  }
  return matches;
}

}  // namespace facet
