#pragma once
// Exhaustive search of the top pyramid level with quantised-orientation response maps (internal
// to facet_shape). Map b holds 127 cos(theta - theta_b) for every pixel, so the score of a
// template (one angle and scale) at every position is a sum of shifted map rows: one
// vectorisable 8-bit add per model point and image row, as in LINE-MOD.

#include <vector>

#include <opencv2/core.hpp>

#include "algorithms/shape/find_shape_model.hpp"
#include "algorithms/shape/shape_model.hpp"

namespace facet::shape_detail {

// Pixels of the top level: a kept maximum over position suppresses the weaker ones this close.
inline constexpr int kPeakReach = 2;

struct Candidate {
  double x = 0.0, y = 0.0;  // position on the current level, pixels
  double angle = 0.0;       // radians
  double scale = 1.0;
  double score = 0.0;
};

// Maxima over position (best template per pixel; maxima of their 3x3 neighbourhood, strongest
// first, kept unless a kept one lies within kPeakReach pixels or a best there lies 0.1 above)
// scoring at least `threshold`, best first, all of them (the caller decides which to track first);
// and where the score has a second peak in angle, the maxima over position and angle scoring at
// least `separateThreshold` as well (response_map_search.cpp; a `separateThreshold` above 1 keeps
// the maxima over position only). `field` is the top level's DirectionField; the search splits its
// rows over `threads` threads. With `spread` > 0 each point takes the best response within `spread`
// pixels in x and y (a part whose contour differs from the model's by that much; not with
// Polarity::IgnoreGlobal, whose sums would need the worst response as well).
std::vector<Candidate> searchTopLevel(const cv::Mat& field, const std::vector<ShapePoint>& points,
                                      const std::vector<double>& angles,
                                      const std::vector<double>& scales, Polarity polarity,
                                      int spread, double threshold, double separateThreshold,
                                      int threads);

}  // namespace facet::shape_detail
