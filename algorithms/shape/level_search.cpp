#include "algorithms/shape/level_search.hpp"

#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

#include "algorithms/shape/shape_similarity.hpp"

namespace facet::shape_detail {

double clampAngle(const Interval& range, double a) {
  if (range.full) return wrapAngle(a);
  return std::clamp(a, range.start, range.start + range.extent);
}

Candidate refineOnLevel(const LevelSearch& s, Candidate c, int radius, int angleSteps) {
  const double aStep = s.level->angleStep;
  const double sStep = s.scaleMax > s.scaleMin ? s.level->scaleStep : 0.0;
  Candidate best = c;
  best.score = -1.0;
  // A climb looks again at the angles and scales next to its new centre, most of which the last
  // one posed already: keep each pose's points for the call.
  std::vector<std::pair<cv::Vec2d, PosedPoints>> posedAt;
  const auto pose = [&](double a, double sc) -> const PosedPoints& {
    for (const auto& [key, posed] : posedAt)
      if (key[0] == a && key[1] == sc) return posed;
    posedAt.emplace_back(cv::Vec2d(a, sc), posePoints(s.level->points, a, sc));
    return posedAt.back().second;
  };
  // The centre's own score first, as the bar the others must reach: most poses around a tracked
  // candidate score below it, and the early termination then abandons them sooner. The pose
  // kept is the same (the first of the best in the loop's order): the safe termination never
  // abandons a pose that ties or beats the bar, which lies below the centre's score by more than
  // the rounding of the directions and of the bound (at the last point it is minScore up to the
  // rounding of its share). Only for the safe termination (greediness 0): a greedy one may abandon
  // the centre itself.
  const double bar =
      s.greediness > 0.0
          ? -1.0
          : scorePose(
                *s.field,
                pose(clampAngle(s.angles, c.angle), std::clamp(c.scale, s.scaleMin, s.scaleMax)),
                cv::Point(cvRound(c.x), cvRound(c.y)), s.polarity, s.minScore, 0.0, s.spread) -
                1e-6;
  for (int climb = 0; climb < 6; ++climb) {
    Candidate centre = climb == 0 ? c : best;
    bool onBorder = false;
    const int ns = sStep > 0.0 ? 1 : 0;
    for (int k = -angleSteps; k <= angleSteps; ++k) {
      const double a = clampAngle(s.angles, centre.angle + k * aStep);
      for (int m = -ns; m <= ns; ++m) {
        const double sc = std::clamp(centre.scale + m * sStep, s.scaleMin, s.scaleMax);
        const PosedPoints& posed = pose(a, sc);
        for (int dy = -radius; dy <= radius; ++dy)
          for (int dx = -radius; dx <= radius; ++dx) {
            const cv::Point at(cvRound(centre.x) + dx, cvRound(centre.y) + dy);
            const double score =
                scorePose(*s.field, posed, at, s.polarity, std::max({s.minScore, best.score, bar}),
                          s.greediness, s.spread);
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

double scoreOnLevel(const LevelSearch& s, const Candidate& c) {
  return scorePose(*s.field, posePoints(s.level->points, c.angle, c.scale),
                   cv::Point(cvRound(c.x), cvRound(c.y)), s.polarity, 0.0, 0.0, s.spread);
}

Candidate interpolate(const LevelSearch& s, Candidate c) {
  // The five scores at the candidate's own angle and scale share its posed points.
  const PosedPoints centre = posePoints(s.level->points, c.angle + 0.0, c.scale + 0.0);
  auto at = [&](double dx, double dy, double da, double ds) {
    const bool turned = da != 0.0 || ds != 0.0;
    const PosedPoints posed =
        turned ? posePoints(s.level->points, c.angle + da, c.scale + ds) : PosedPoints{};
    return scorePose(*s.field, turned ? posed : centre,
                     cv::Point(cvRound(c.x + dx), cvRound(c.y + dy)), s.polarity, 0.0, 0.0,
                     s.spread);
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

}  // namespace facet::shape_detail
