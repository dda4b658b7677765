#include "algorithms/shape/find_shape_model.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "algorithms/shape/image_gradients.hpp"
#include "algorithms/shape/least_squares_refinement.hpp"
#include "algorithms/shape/level_search.hpp"
#include "algorithms/shape/model_symmetry.hpp"
#include "algorithms/shape/refinement_choice.hpp"
#include "algorithms/shape/response_map_search.hpp"
#include "algorithms/shape/shape_similarity.hpp"

namespace facet {
namespace {

using shape_detail::Candidate;
using shape_detail::DirectionField;
using shape_detail::Interval;
using shape_detail::LevelSearch;
using shape_detail::refineOnLevel;

using shape_detail::kFinalFactor;
using shape_detail::kMiddleFactor;
using shape_detail::kTopFactor;

constexpr double kTwoPi = 2.0 * std::numbers::pi;

// ---------------------------------------------------------------------------------------------
// Search space

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

// ---------------------------------------------------------------------------------------------
// Finishing a level-0 candidate: a wider look, subpixel refinement, the refined score.

constexpr std::size_t kClusterRefined = 2;  // other candidates on the same part refined as well
constexpr double kClusterMargin = 0.1;      // ... if their level-0 score is at most this lower
constexpr double kSkipRefinement = 0.15;    // below minScore by more: not worth refining

struct Finished {
  Pose2D pose;
  double score = 0.0;
  double residual = 0.0;
};

struct Finisher {
  const cv::Mat& image;
  const ShapeModel& model;
  const Box& box;
  const LevelSearch& search;  // level 0
  DirectionField& field;
  const FindParams& params;
  bool scaleRange;

  double scoreAt(const Pose2D& pose) const {
    const int margin = 2 + params.maxDeformation;
    field.ensure(placedBox(box, pose).boundingRect() + cv::Size(2 * margin, 2 * margin) -
                 cv::Point(margin, margin));
    return shape_detail::refinedScore(field.directions(), model, pose, params.polarity,
                                      params.maxDeformation);
  }

  struct Refinement {
    shape_detail::Refined fit;
    bool fittedFully;  // see shape_detail::RefinementOutcome
  };

  // The least-squares refinement from `start`. A model with a scale range fits its scale. A
  // fixed-scale model may still meet a part a percent larger or smaller (lens, distance): it is
  // refined both with the scale free and at the model's scale, and the fit that lays more of the
  // model's points on edges within the tolerance the closer of the two reached (its own final
  // cut-off) is the part's. The other one has let something else stand in for part of the part:
  // an occluder's border parallel to a hidden edge pulls a free scale 1-2% and the pose a pixel
  // or more with it, at ten times the residual of the fit at the model's scale; at the model's
  // scale, a part truly a percent larger fits at neither end. A free scale that wins but goes
  // beyond the tolerance is not followed: the part is held at the model's scale and is judged
  // as not fitted fully. Where neither fit is exact, a third leaves out the points hidden at the
  // start (below).
  Refinement refineFrom(const shape_detail::LeastSquaresRefinement& refinement,
                        const Pose2D& start) const {
    const double tolerance = params.refineScaleTolerance;
    if (scaleRange) return {refinement.refine(start, true), true};
    if (tolerance <= 0.0) {
      // The scale is held: the fit judges whether the part has it. An exact fit does (a part a
      // percent off fits at neither end, its points tenths of a pixel off edges).
      const shape_detail::Refined modelScale = refinement.refine(start, false);
      return {modelScale, modelScale.exact()};
    }
    const shape_detail::Refined freeScale = refinement.refine(start, true);
    const double scaleChange = std::abs(freeScale.pose.scale / start.scale - 1.0);
    // An exact free fit at a scale within two standard errors of the model's leaves nothing for
    // the fit at the model's scale to find.
    if (freeScale.exact() && scaleChange <= 2.0 * freeScale.scaleSigma && scaleChange <= tolerance)
      return {freeScale, true};
    const shape_detail::Refined modelScale = refinement.refine(start, false);
    const bool freeWithin = scaleChange <= tolerance;
    if (!freeScale.exact() && !modelScale.exact()) {
      // Neither fit is exact (a photograph, or much of the part hidden): the points with no image
      // gradient near them at the start (hidden) are left out of a third fit, so that an
      // occluder's border cannot pull it, and it is kept where it lays more points on edges than
      // the other fits within the tolerance.
      const shape_detail::Refined visibleOnly = refinement.refine(
          start, true, shape_detail::pointsNearGradients(field.directions(), model, start));
      if (visibleOnly.status.ok() &&
          std::abs(visibleOnly.pose.scale / start.scale - 1.0) <= tolerance) {
        double cutoff = visibleOnly.cutoff;
        if (modelScale.status.ok()) cutoff = std::min(cutoff, modelScale.cutoff);
        if (freeScale.status.ok() && freeWithin) cutoff = std::min(cutoff, freeScale.cutoff);
        const double support = refinement.support(visibleOnly, cutoff);
        if ((!modelScale.status.ok() || support > refinement.support(modelScale, cutoff)) &&
            (!freeScale.status.ok() || !freeWithin ||
             support > refinement.support(freeScale, cutoff)))
          return {visibleOnly, true};
      }
    }
    if (!freeScale.status.ok()) return {modelScale, modelScale.exact()};
    if (!modelScale.status.ok()) return {freeWithin ? freeScale : modelScale, freeWithin};
    const double cutoff = std::min(freeScale.cutoff, modelScale.cutoff);
    const bool freeFits =
        refinement.support(freeScale, cutoff) > refinement.support(modelScale, cutoff);
    if (!freeFits) return {modelScale, true};
    return {freeWithin ? freeScale : modelScale, freeWithin};
  }

  // A candidate's pose before the least-squares refinement: after a wider look, interpolated
  // unless no subpixel pose is asked for.
  struct Started {
    Finished start;
    bool refine = false;  // the least-squares refinement is tried from it
  };

  std::optional<Started> begin(Candidate c) const {
    const int margin = 4 + params.maxDeformation;
    field.ensure(placedBox(box, {c.x, c.y, c.angle, c.scale}).boundingRect() +
                 cv::Size(2 * margin, 2 * margin) - cv::Point(margin, margin));
    // Occluders and clutter can bend the score surface so that tracking stops on a secondary
    // peak next to the true one; a wider look around each match about to be returned finds it.
    // With a deformation allowed the score is flat within maxDeformation of the part (on an exact
    // part it is 1 across that square): the look is taken on the rigid score, whose peak is where
    // the model's points meet their edges exactly, and the match keeps its tolerant score.
    LevelSearch rigid = search;
    rigid.spread = 0;
    if (search.spread == 0) {
      if (const Candidate wide = refineOnLevel(search, c, 2, 3); wide.score > c.score) c = wide;
    } else {
      rigid.minScore = 0.0;
      Candidate centred = refineOnLevel(rigid, c, search.spread + 2, 3);
      centred.score = shape_detail::scoreOnLevel(search, centred);
      c = centred;
    }
    if (c.score < 0.0) return std::nullopt;
    if (params.subpixel == SubpixelMode::None)
      return Started{{{c.x, c.y, c.angle, c.scale}, c.score}};
    c = shape_detail::interpolate(rigid, c);
    const Pose2D start{c.x, c.y, c.angle, c.scale};
    const Finished interpolated{start, scoreAt(start)};
    // The least-squares refinement costs a subpixel edge detection: it is spent only on poses
    // that can become matches (it moves a score by a few hundredths, not by kSkipRefinement).
    return Started{interpolated, params.subpixel == SubpixelMode::LeastSquares &&
                                     interpolated.score >= params.minScore - kSkipRefinement};
  }

  // The region whose edges the refinement from `start` may use, image pixels.
  cv::Rect refinementRegion(const Pose2D& start) const {
    return placedBox(box, start).boundingRect() + cv::Size(8, 8) - cv::Point(4, 4);
  }

  // The least-squares refinement from `from` on the part's edges: its pose where it is kept
  // (refinement_choice.hpp), else `from`.
  Finished refined(const shape_detail::LeastSquaresRefinement& refinement,
                   const Finished& from) const {
    const Pose2D& start = from.pose;
    const auto [r, fittedFully] = refineFrom(refinement, start);
    // A refinement that wanders off by more than the search's own uncertainty has locked onto
    // something else.
    if (!r.status.ok() || std::hypot(r.pose.x - start.x, r.pose.y - start.y) >= 3.0) return from;
    const Finished fit{r.pose, scoreAt(r.pose), r.residual};
    const shape_detail::RefinementOutcome outcome{.startScore = from.score,
                                                  .refinedScore = fit.score,
                                                  .startSupport = r.startSupport,
                                                  .refinedSupport = r.support,
                                                  .fittedFully = fittedFully,
                                                  .exactFit = r.exact()};
    if (!shape_detail::keepsRefinedPose(outcome)) return from;
    return Finished{fit.pose, shape_detail::keptRefinementScore(outcome), fit.residual};
  }

  // The best of one part's alternative poses, each finished. Their refinements share one
  // subpixel edge detection, over the union of their regions: the alternatives lie on the same
  // part, and detecting its edges was most of each refinement's cost (16 detections of 2-5 ms
  // for six propellers on a light table, of 78 ms in all).
  std::optional<Finished> best(const std::vector<Candidate>& alternatives) const {
    std::vector<Started> started;
    std::vector<Pose2D> starts;
    cv::Rect region;
    for (const Candidate& alt : alternatives) {
      const std::optional<Started> s = begin(alt);
      if (!s) continue;
      started.push_back(*s);
      if (!s->refine) continue;
      const cv::Rect here = refinementRegion(s->start.pose);
      region = starts.empty() ? here : (region | here);
      starts.push_back(s->start.pose);
    }
    std::optional<shape_detail::LeastSquaresRefinement> refinement;
    if (!starts.empty()) {
      // A fit may change the scale by the tolerance, or with a scale range by about its step.
      const double scaleFreedom =
          scaleRange ? std::max(params.refineScaleTolerance, 2.0 * model.levels[0].scaleStep)
                     : params.refineScaleTolerance;
      refinement.emplace(image, model, region, params.polarity, starts, scaleFreedom);
    }
    std::optional<Finished> bestSoFar;
    for (const Started& s : started) {
      const Finished f = s.refine ? refined(*refinement, s.start) : s.start;
      if (!bestSoFar || f.score > bestSoFar->score) bestSoFar = f;
    }
    return bestSoFar;
  }
};

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
  if (!(p.refineScaleTolerance >= 0.0 && p.refineScaleTolerance <= kMaxScaleTolerance))
    throw std::invalid_argument("findShapeModel: refineScaleTolerance must lie in [0, 0.1]");
  if (p.maxDeformation < 0 || p.maxDeformation > kMaxDeformation)
    throw std::invalid_argument("findShapeModel: maxDeformation must lie in [0, " +
                                std::to_string(kMaxDeformation) + "] pixels");
  if (p.maxDeformation > 0 && p.polarity == Polarity::IgnoreGlobal)
    throw std::invalid_argument(
        "findShapeModel: maxDeformation cannot be combined with Polarity::IgnoreGlobal (use "
        "IgnoreLocal)");
}

// FindParams::maxDeformation on pyramid level l, in that level's pixels, rounded down: the
// pyramid's smoothing absorbs a deformation below a pixel of the level, and spreading a coarse
// level by a whole pixel for it let 8 times as many candidates reach the levels below (a
// photograph of 36 LEDs, 1 px) and found no part more.
int spreadOnLevel(int maxDeformation, int l) {
  return maxDeformation >> l;
}

// The angle steps of a level that a second, wider look covers on either side of a candidate from
// the level above: two steps of the level above. A part partly hidden can peak on the top level a
// step or two from its own angle, where the occluder's or clutter's edges line up with the
// model's; the usual look, one step of the level below (half a step above), left such a part to
// climb from there, and the climb stopped on the wrong side's peak. The wider look's peak is
// tracked beside the near one where the two differ: either may be the part, and the levels below
// tell them apart.
int wideLookSteps(const ShapeLevel& above, const ShapeLevel& below) {
  if (!(below.angleStep > 0.0) || !(above.angleStep > 0.0)) return 1;
  return std::max(1, static_cast<int>(std::ceil(2.0 * above.angleStep / below.angleStep - 1e-9)));
}

// Two tracked poses on one level that are the same peak: within a pixel and an angle step.
bool sameLevelPose(const Candidate& a, const Candidate& b, double angleStep) {
  return std::abs(a.x - b.x) <= 1.0 && std::abs(a.y - b.y) <= 1.0 &&
         std::abs(wrapAngle(a.angle - b.angle)) <= angleStep * 1.001 &&
         std::abs(a.scale - b.scale) < 1e-9;
}

// The top-level candidates tracked first when a number of matches is asked for: the best
// 20 + 10 per match (the others follow against the score to beat).
constexpr std::size_t kFirstTracked = 20;
constexpr std::size_t kFirstTrackedPerMatch = 10;

// Each candidate's near-symmetric turns, appended: the top level sees the part coarsest, and where
// the model is nearly symmetric there the turned pose may be the one it keeps and the right one
// absent. The turns are tracked down the pyramid beside the candidates (the levels below tell
// them apart); turns outside the searched angles are not.
void addSymmetricTurns(std::vector<Candidate>& candidates, const ShapeModel& model,
                       const Interval& angles, int top) {
  if (model.symmetries.empty()) return;
  const double f = std::ldexp(1.0, -top);
  const std::size_t found = candidates.size();
  for (std::size_t i = 0; i < found; ++i) {
    const Candidate c = candidates[i];
    for (ModelSymmetry sym : model.symmetries) {
      sym.centre *= f;
      const Pose2D turned = turnedBy({c.x, c.y, c.angle, c.scale}, sym);
      double a = wrapAngle(turned.angle);
      if (!angles.full) {
        // The turn's angle taken to the first one at or after the range's start.
        double past = std::fmod(a - angles.start, kTwoPi);
        if (past < 0.0) past += kTwoPi;
        if (past > angles.extent) continue;
        a = angles.start + past;
      }
      candidates.push_back({std::round(turned.x), std::round(turned.y), a, c.scale, c.score});
    }
  }
}

// Each candidate's neighbours one tracked period away (ShapeModel::trackedPeriods), appended: where
// a pattern repeats within the top level's reach, the top level keeps one maximum among the
// periods' poses, and it may be a neighbour's. The levels below tell them apart. Only a neighbour
// that the top level scores within kClusterMargin of the candidate (best of the 3x3 pixels around
// it) could still be the part's, as for the candidates on one part at the finish. Tracking every
// neighbour made a package with rows of pins search 60% longer (bench_shape_real's board_dip, 5.1
// -> 8.2 ms), tracking these 25% (6.4 ms).
void addPeriodNeighbours(std::vector<Candidate>& candidates, const ShapeModel& model,
                         const cv::Mat& topField, Polarity polarity, int spread, int top) {
  if (model.trackedPeriods.empty()) return;
  const double f = std::ldexp(1.0, -top);
  const std::vector<ShapePoint>& points = model.levels[static_cast<std::size_t>(top)].points;
  const std::size_t found = candidates.size();
  for (std::size_t i = 0; i < found; ++i) {
    const Candidate c = candidates[i];
    const Pose2D pose{c.x, c.y, c.angle, c.scale};
    const shape_detail::PosedPoints posed = shape_detail::posePoints(points, c.angle, c.scale);
    for (const ModelPeriod& period : model.trackedPeriods) {
      const cv::Point2d shift = pose.applyToVector(period.shift * f);
      const cv::Point at(cvRound(c.x + shift.x), cvRound(c.y + shift.y));
      if (shape_detail::bestScoreAround(topField, posed, at, polarity, spread) >=
          c.score - kClusterMargin)
        candidates.push_back({double(at.x), double(at.y), c.angle, c.scale, c.score});
    }
  }
}

// Candidates of the top level tracked down the pyramid to level 0.
struct Tracker {
  Tracker(std::vector<DirectionField>& fields, const ShapeModel& model, const FindParams& params,
          const LevelSearch& base, int top)
      : fields(fields), model(model), params(params), base(base), top(top) {
    // How far around a candidate each level's directions are needed: the model's reach there.
    for (int l = 0; l < top; ++l) {
      double radius = 0.0;
      for (const auto& p : model.levels[l].points)
        radius = std::max(radius, std::hypot(double(p.position.x), double(p.position.y)));
      reach.push_back(static_cast<int>(std::ceil(radius * base.scaleMax)) + 16 +
                      spreadOnLevel(params.maxDeformation, l));
    }
  }

  std::vector<DirectionField>& fields;
  const ShapeModel& model;
  const FindParams& params;
  const LevelSearch& base;  // angles, scales, polarity, greediness
  int top;
  std::vector<int> reach;  // per level below the top, pixels of the level

  // The score a candidate must keep on level l: on the levels between the top and 0 a part
  // scoring `minScore` at the end scores at least kMiddleFactor of it, on level 0 before
  // refinement kFinalFactor.
  [[nodiscard]] double threshold(double minScore, int l) const {
    return minScore * (l > 0                                   ? kMiddleFactor
                       : params.subpixel == SubpixelMode::None ? 1.0
                                                               : kFinalFactor);
  }

  // The candidates that hold on every level (threshold()). Called with FindParams::minScore, or
  // with a higher score a candidate has to reach to be returned at all.
  std::vector<Candidate> toLevelZero(std::vector<Candidate> candidates, double minScore) const {
    LevelSearch search = base;
    for (int l = top - 1; l >= 0; --l) {
      search.field = &fields[l].directions();
      search.level = &model.levels[l];
      search.spread = spreadOnLevel(params.maxDeformation, l);
      // Directions are needed only around the candidates.
      const int around = reach[static_cast<std::size_t>(l)];
      for (const Candidate& c : candidates)
        fields[l].ensure(cv::Rect(cvRound(2 * c.x) - around, cvRound(2 * c.y) - around,
                                  2 * around + 1, 2 * around + 1));
      search.minScore = threshold(minScore, l);
      // Each candidate is tracked on its own (the field is read-only here), in parallel when
      // threads > 1; kept in their order, so the result is the same for any number of threads.
      // A candidate may also leave a second peak (see wideLookSteps).
      std::vector<std::array<Candidate, 2>> tracked(candidates.size());
      const bool belowTop = l == top - 1;
      const int wideSteps = wideLookSteps(model.levels[l + 1], model.levels[l]);
      auto track = [&](const cv::Range& r) {
        for (int i = r.start; i < r.end; ++i) {
          Candidate c = candidates[static_cast<std::size_t>(i)];
          c.x *= 2.0;
          c.y *= 2.0;
          auto& out = tracked[static_cast<std::size_t>(i)];
          out[0] = refineOnLevel(search, c, 2);
          out[1].score = -1.0;
          // Also around a candidate whose near look fails but which scored this level's bar on
          // the level above: it has lost its angle rather than its part. On a texture the top
          // level's best angle at the part's pixel lay 2.3 of its steps from the part's; the near
          // look from there scored 0.47, the wider one climbed to 0.95, and a part scoring 0.99
          // was missed. Further down the same happens where the level above sees only the
          // part's outline and this one its texture too (a patch of orange peel: 30 points on
          // level 1, 449 on level 0; level 1 left the angle 2.6 degrees off, three steps of
          // level 0, where the texture no longer scores). There a look of 3x3 positions is
          // enough, the angle is what it seeks; from a candidate that reached the minimum score
          // itself on the level above, 5x5 as the near look: its best pixel there may be off
          // with its angle (on a textured disc turned -121.5 degrees level 1's peak, 0.88, lay
          // a pixel of its own and 1.4 degrees from the part's, and the part, 0.92, two pixels
          // away below, was missed). Most candidates that fail are clutter below the minimum,
          // for which the wider positions cost a busy photograph a quarter more time. Below the
          // top, also beside a candidate that holds: only a peak that could still be chosen
          // over it (as the finish does: within kClusterMargin).
          const bool holds = out[0].score >= search.minScore;
          // c.score: the level above's
          if (wideSteps > 1 && ((holds && belowTop) || (!holds && c.score >= search.minScore))) {
            LevelSearch wideSearch = search;
            if (holds)
              wideSearch.minScore = std::max(search.minScore, out[0].score - kClusterMargin);
            const int radius = holds || c.score >= params.minScore ? 2 : 1;
            const Candidate wide = refineOnLevel(wideSearch, c, radius, wideSteps);
            if (wide.score >= wideSearch.minScore &&
                !sameLevelPose(wide, out[0], search.level->angleStep))
              out[1] = wide;
          }
        }
      };
      const cv::Range all(0, static_cast<int>(candidates.size()));
      if (params.threads > 1 && candidates.size() > 1)
        cv::parallel_for_(all, track, static_cast<double>(candidates.size()));
      else
        track(all);
      std::vector<Candidate> next;
      for (const auto& peaks : tracked)
        for (const Candidate& r : peaks)
          if (r.score >= search.minScore) next.push_back(r);
      candidates.swap(next);
    }
    if (top == 0)
      std::erase_if(candidates,
                    [&](const Candidate& c) { return c.score < threshold(minScore, 0); });
    return candidates;
  }
};

// The level-0 score a later candidate has to reach to be returned: the score of the last of the
// FindParams::numMatches best level-0 candidates that reach the minimum score and do not overlap
// each other (as the finish picks them). FindParams::minScore while there are fewer. Such a
// candidate is returned unless the finish scores it below the minimum: its score is then the
// better of the refined and the interpolated pose's (refinement_choice.hpp), close to its
// level-0 one.
double scoreToBeat(std::vector<Candidate> candidates, const Box& box, const FindParams& params) {
  std::sort(candidates.begin(), candidates.end(),
            [](const Candidate& a, const Candidate& b) { return a.score > b.score; });
  std::vector<cv::RotatedRect> taken;
  for (const Candidate& c : candidates) {
    if (c.score < params.minScore) break;
    const cv::RotatedRect here = placedBox(box, {c.x, c.y, c.angle, c.scale});
    if (std::any_of(taken.begin(), taken.end(),
                    [&](const cv::RotatedRect& t) { return overlap(here, t) > params.maxOverlap; }))
      continue;
    taken.push_back(here);
    if (static_cast<int>(taken.size()) == params.numMatches) return c.score;
  }
  return params.minScore;
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
  fields[top].ensureAll();
  // A second peak in angle at a pixel is tracked where it already scores the bar of the level
  // below; not for a model that every turn maps onto itself (a candy: its score is flat in angle,
  // and the second peaks only doubled the candidates). A model's near-symmetric turns, tracked by
  // addSymmetricTurns, do not make them redundant: on a patch of a calibration chessboard, whose
  // top level has near-symmetries at 73 and -75 degrees, the part's pixel was suppressed by a
  // neighbouring square's pose at a half turn and the part (0.999) was missed; of 9 patches of one
  // such photograph whose part was missed or outscored, 8 are found with the second peaks.
  const double separatePeaks = mapsOntoItselfAtEveryTurn(topLevel.points, topLevel.angleStep)
                                   ? 2.0
                                   : kMiddleFactor * params.minScore;
  std::vector<Candidate> candidates = shape_detail::searchTopLevel(
      fields[top].directions(), topLevel.points, angleSamples(*angles, topLevel.angleStep),
      scaleSamples(scaleMin, scaleMax, topLevel.scaleStep), params.polarity,
      spreadOnLevel(params.maxDeformation, top), kTopFactor * params.minScore, separatePeaks,
      params.threads);

  // Every top-level candidate is tracked: the top level sees a small part coarsest, and on a
  // busy photograph a part a third hidden ranked 100th-220th there behind clutter (a crystal on
  // a circuit board, scoring 0.71-0.76 at level 0) and was dropped when only the first 30 were
  // kept. When a number of matches is asked for, the best ones go first; the others are then
  // tracked against the level-0 score they would have to beat to be returned (scoreToBeat), which
  // lets the safe early termination abandon most of them sooner.
  std::vector<Candidate> later;
  if (params.numMatches > 0) {
    const std::size_t first = kFirstTracked + kFirstTrackedPerMatch * params.numMatches;
    if (candidates.size() > first) {
      later.assign(candidates.begin() + static_cast<std::ptrdiff_t>(first), candidates.end());
      candidates.resize(first);
    }
  }
  addSymmetricTurns(candidates, model, *angles, top);
  addSymmetricTurns(later, model, *angles, top);
  const int topSpread = spreadOnLevel(params.maxDeformation, top);
  addPeriodNeighbours(candidates, model, fields[top].directions(), params.polarity, topSpread, top);
  addPeriodNeighbours(later, model, fields[top].directions(), params.polarity, topSpread, top);

  LevelSearch search;
  search.angles = *angles;
  search.scaleMin = scaleMin;
  search.scaleMax = scaleMax;
  search.polarity = params.polarity;
  search.greediness = params.greediness;
  const Box box = modelBox(model);
  const Tracker tracker(fields, model, params, search, top);
  candidates = tracker.toLevelZero(std::move(candidates), params.minScore);
  if (!later.empty()) {
    const double toBeat = scoreToBeat(candidates, box, params);
    std::vector<Candidate> more = tracker.toLevelZero(std::move(later), toBeat);
    candidates.insert(candidates.end(), more.begin(), more.end());
  }
  std::sort(candidates.begin(), candidates.end(),
            [](const Candidate& a, const Candidate& b) { return a.score > b.score; });

  // Best first: refine, check the refined score, suppress overlaps with the matches kept. Each
  // match is chosen among its alternatives (the model's near-symmetric turns and other candidates
  // on the same part), all refined, so that the coarse levels' pick does not decide.
  search.field = &fields[0].directions();
  search.level = &model.levels[0];
  search.spread = spreadOnLevel(params.maxDeformation, 0);
  search.minScore = params.minScore * kFinalFactor;
  const bool fixedScale = scaleMax <= scaleMin;
  const Finisher finisher{image, model, box, search, fields[0], params, !fixedScale};
  std::vector<ShapeMatch> matches;
  std::vector<cv::RotatedRect> keptBoxes;
  auto clashes = [&](const Pose2D& pose) {
    const cv::RotatedRect r = placedBox(box, pose);
    for (const auto& k : keptBoxes)
      if (overlap(r, k) > params.maxOverlap) return true;
    return false;
  };
  std::vector<bool> used(candidates.size(), false);
  for (std::size_t i = 0; i < candidates.size(); ++i) {
    if (params.numMatches > 0 && static_cast<int>(matches.size()) >= params.numMatches) break;
    if (used[i]) continue;
    used[i] = true;
    const Candidate& c = candidates[i];
    if (clashes({c.x, c.y, c.angle, c.scale})) continue;
    std::vector<Candidate> alternatives{c};
    for (const ModelSymmetry& sym : model.symmetries) {
      const Pose2D turned = turnedBy({c.x, c.y, c.angle, c.scale}, sym);
      alternatives.push_back({std::round(turned.x), std::round(turned.y),
                              shape_detail::clampAngle(*angles, turned.angle), c.scale, -1.0});
    }
    const cv::RotatedRect here = placedBox(box, {c.x, c.y, c.angle, c.scale});
    for (std::size_t j = i + 1, taken = 0; j < candidates.size() && taken < kClusterRefined; ++j) {
      const Candidate& o = candidates[j];
      if (used[j] ||
          overlap(here, placedBox(box, {o.x, o.y, o.angle, o.scale})) <= params.maxOverlap)
        continue;
      used[j] = true;
      const bool same = std::hypot(o.x - c.x, o.y - c.y) < 1.5 &&
                        std::abs(wrapAngle(o.angle - c.angle)) < 1.5 * search.level->angleStep;
      if (!same && o.score >= c.score - kClusterMargin) alternatives.push_back(o), ++taken;
    }
    const std::optional<Finished> best = finisher.best(alternatives);
    if (!best || best->score < params.minScore || clashes(best->pose)) continue;
    ShapeMatch m;
    m.x = best->pose.x;
    m.y = best->pose.y;
    m.angle = wrapAngle(best->pose.angle);
    m.scale = best->pose.scale;
    m.score = best->score;
    m.residual = best->residual;
    m.contour.reserve(model.finePoints.size());
    const Pose2D::Map toImage = best->pose.map();
    for (const auto& p : model.finePoints) m.contour.push_back(toImage(p.position));
    keptBoxes.push_back(placedBox(box, best->pose));
    matches.push_back(std::move(m));
  }
  std::sort(matches.begin(), matches.end(),
            [](const ShapeMatch& a, const ShapeMatch& b) { return a.score > b.score; });
  return matches;
}

}  // namespace facet
