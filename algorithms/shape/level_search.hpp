#pragma once
// Searching one pyramid level around a known pose (internal to facet_shape): the local search
// that tracks a candidate down the pyramid and the score-parabola interpolation on level 0.

#include <vector>

#include <opencv2/core.hpp>

#include "algorithms/shape/find_shape_model.hpp"
#include "algorithms/shape/response_map_search.hpp"
#include "algorithms/shape/shape_model.hpp"

namespace facet::shape_detail {

// The score a part must keep on each level to be tracked, relative to FindParams::minScore: a part
// scoring the minimum at the end is assumed to score at least this share of it there. The
// automatic pyramid holds a model's top level to it (pyramid_depth_check.hpp).
inline constexpr double kTopFactor = 0.7;     // the top level
inline constexpr double kMiddleFactor = 0.8;  // the levels between the top and 0
inline constexpr double kFinalFactor = 0.8;   // level 0 before refinement (the fit's score decides)

struct Interval {
  double start = 0.0;
  double extent = 0.0;
  bool full = false;  // angle: the whole circle
};

// An angle moved into the interval (wrapped for the full circle, clamped otherwise).
double clampAngle(const Interval& range, double a);

struct LevelSearch {
  const cv::Mat* field = nullptr;  // the level's DirectionField directions
  const ShapeLevel* level = nullptr;
  Interval angles;
  double scaleMin = 1.0, scaleMax = 1.0;
  Polarity polarity = Polarity::Use;
  double minScore = 0.0;
  double greediness = 0.0;
  int spread = 0;  // FindParams::maxDeformation on this level, pixels of the level
};

// Best pose in a neighbourhood of `c`: (2 radius + 1)^2 positions x (2 angleSteps + 1) angles x 3
// scales, climbing while the best lies on the border. Score -1 when nothing reaches minScore.
Candidate refineOnLevel(const LevelSearch& s, Candidate c, int radius, int angleSteps = 1);

// The score of one pose on the level (no early termination).
double scoreOnLevel(const LevelSearch& s, const Candidate& c);

// Score-parabola interpolation around a level-0 maximum in x, y, angle and scale.
Candidate interpolate(const LevelSearch& s, Candidate c);

}  // namespace facet::shape_detail
