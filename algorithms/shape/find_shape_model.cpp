#include "algorithms/shape/find_shape_model.hpp"

#include <algorithm>
#include <cmath>
#include <optional>
#include <stdexcept>

#include <opencv2/imgproc.hpp>

#include "algorithms/shape/image_gradients.hpp"
#include "algorithms/shape/least_squares_refinement.hpp"
#include "algorithms/shape/response_map_search.hpp"
#include "algorithms/shape/shape_similarity.hpp"

namespace facet {
namespace {

using shape_detail::Candidate;
using shape_detail::DirectionField;
using shape_detail::PosedPoints;
using shape_detail::posePoints;
using shape_detail::scorePose;

constexpr double kTwoPi = 2.0 * std::numbers::pi;
constexpr double kTopFactor = 0.7;     // top-level threshold, relative to minScore
constexpr double kMiddleFactor = 0.8;  // threshold on levels between top and 0
constexpr double kFinalFactor = 0.8;   // level 0 before refinement (the refined score decides)

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

// Best pose in a neighbourhood of `c`: (2 radius + 1)^2 positions x (2 angleSteps + 1) angles x 3
// scales, climbing while the best lies on the border.
Candidate refineOnLevel(const LevelSearch& s, Candidate c, int radius, int angleSteps = 1) {
  const double aStep = s.level->angleStep;
  const double sStep = s.scaleMax > s.scaleMin ? s.level->scaleStep : 0.0;
  Candidate best = c;
  best.score = -1.0;
  for (int climb = 0; climb < 6; ++climb) {
    Candidate centre = climb == 0 ? c : best;
    bool onBorder = false;
    const int ns = sStep > 0.0 ? 1 : 0;
    for (int k = -angleSteps; k <= angleSteps; ++k) {
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
                         (std::abs(k) == angleSteps && aStep > 0.0) || m != 0;
            }
          }
      }
    }
    if (!onBorder || best.score < s.minScore) break;
    radius = 1;
    angleSteps = 1;
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
// Matches in the image: oriented boxes for the overlap test and the refinement's region.

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
  std::vector<DirectionField> fields;
  {
    // 8-bit images stay 8-bit (fast pyramid and Sobel); 16-bit ones go to the 8-bit float scale.
    cv::Mat grey = image.depth() == CV_8U ? image : shape_detail::toGreyFloat(image);
    for (int l = 0; l < levels; ++l) {
      if (l > 0) cv::pyrDown(grey, grey);
      fields.emplace_back(grey, model.minContrast);
    }
  }

  const int top = levels - 1;
  const ShapeLevel& topLevel = model.levels[top];
  const int maxCandidates = params.numMatches == 0 ? 400 : 20 + 10 * params.numMatches;
  fields[top].ensureAll();
  std::vector<Candidate> candidates = shape_detail::searchTopLevel(
      fields[top].directions(), topLevel.points, angleSamples(*angles, topLevel.angleStep),
      scaleSamples(scaleMin, scaleMax, topLevel.scaleStep), params.polarity,
      kTopFactor * params.minScore, params.threads, maxCandidates);

  LevelSearch search;
  search.angles = *angles;
  search.scaleMin = scaleMin;
  search.scaleMax = scaleMax;
  search.polarity = params.polarity;
  search.greediness = params.greediness;
  for (int l = top - 1; l >= 0; --l) {
    search.field = &fields[l].directions();
    search.level = &model.levels[l];
    // Directions are needed only around the candidates.
    double levelRadius = 0.0;
    for (const auto& p : model.levels[l].points)
      levelRadius = std::max(levelRadius, std::hypot(double(p.position.x), double(p.position.y)));
    const int reach = static_cast<int>(std::ceil(levelRadius * scaleMax)) + 16;
    for (const Candidate& c : candidates)
      fields[l].ensure(cv::Rect(cvRound(2 * c.x) - reach, cvRound(2 * c.y) - reach, 2 * reach + 1,
                                2 * reach + 1));
    search.minScore = params.minScore * (l > 0                                   ? kMiddleFactor
                                         : params.subpixel == SubpixelMode::None ? 1.0
                                                                                 : kFinalFactor);
    // Each candidate is tracked on its own (the field is read-only here), in parallel when
    // threads > 1; kept in their order, so the result is the same for any number of threads.
    std::vector<Candidate> tracked(candidates.size());
    auto track = [&](const cv::Range& r) {
      for (int i = r.start; i < r.end; ++i) {
        Candidate c = candidates[static_cast<std::size_t>(i)];
        c.x *= 2.0;
        c.y *= 2.0;
        tracked[static_cast<std::size_t>(i)] = refineOnLevel(search, c, 2);
      }
    };
    const cv::Range all(0, static_cast<int>(candidates.size()));
    if (params.threads > 1 && candidates.size() > 1)
      cv::parallel_for_(all, track, static_cast<double>(candidates.size()));
    else
      track(all);
    std::vector<Candidate> next;
    for (const Candidate& r : tracked)
      if (r.score >= search.minScore) next.push_back(r);
    candidates.swap(next);
  }
  if (top == 0) {
    const double keep =
        params.minScore * (params.subpixel == SubpixelMode::None ? 1.0 : kFinalFactor);
    std::erase_if(candidates, [&](const Candidate& c) { return c.score < keep; });
  }
  std::sort(candidates.begin(), candidates.end(),
            [](const Candidate& a, const Candidate& b) { return a.score > b.score; });

  // Best first: refine, check the refined score, suppress overlaps with the matches kept.
  const Box box = modelBox(model);
  search.field = &fields[0].directions();
  search.level = &model.levels[0];
  std::vector<ShapeMatch> matches;
  std::vector<cv::RotatedRect> keptBoxes;
  auto clashes = [&](const Pose2D& pose) {
    const cv::RotatedRect r = placedBox(box, pose);
    for (const auto& k : keptBoxes)
      if (overlap(r, k) > params.maxOverlap) return true;
    return false;
  };
  for (Candidate c : candidates) {
    if (params.numMatches > 0 && static_cast<int>(matches.size()) >= params.numMatches) break;
    if (clashes({c.x, c.y, c.angle, c.scale})) continue;
    ShapeMatch m;
    // Occluders and clutter can bend the score surface so that tracking stops on a secondary
    // peak next to the true one; a wider look around each match about to be returned finds it.
    if (const Candidate wide = refineOnLevel(search, c, 2, 3); wide.score > c.score) c = wide;
    if (params.subpixel != SubpixelMode::None) c = interpolate(search, c);
    Pose2D pose{c.x, c.y, c.angle, c.scale};
    if (params.subpixel == SubpixelMode::LeastSquares) {
      const cv::Rect roi = placedBox(box, pose).boundingRect() + cv::Size(8, 8) - cv::Point(4, 4);
      const shape_detail::Refined r = shape_detail::refineLeastSquares(
          image, model, roi, pose, params.polarity, scaleMax > scaleMin);
      // A refinement that wanders off by more than the search's own uncertainty has locked onto
      // something else.
      if (r.ok && std::hypot(r.pose.x - pose.x, r.pose.y - pose.y) < 3.0) {
        pose = r.pose;
        m.residual = r.residual;
      }
    }
    if (params.subpixel != SubpixelMode::None) {
      fields[0].ensure(placedBox(box, pose).boundingRect() + cv::Size(4, 4) - cv::Point(2, 2));
      c.score = shape_detail::refinedScore(fields[0].directions(), model, pose, params.polarity);
      if (c.score < params.minScore || clashes(pose)) continue;
    }
    m.x = pose.x;
    m.y = pose.y;
    m.angle = wrapAngle(pose.angle);
    m.scale = pose.scale;
    m.score = c.score;
    m.contour.reserve(model.finePoints.size());
    for (const auto& p : model.finePoints) m.contour.push_back(pose.apply(p.position));
    keptBoxes.push_back(placedBox(box, pose));
    matches.push_back(std::move(m));
  }
  std::sort(matches.begin(), matches.end(),
            [](const ShapeMatch& a, const ShapeMatch& b) { return a.score > b.score; });
  return matches;
}

}  // namespace facet
