#pragma once
// Near-symmetries of a shape model: rotations about the centre of its edge points that map the
// model (almost) onto itself, such as the quarter turns of a cross whose arms differ slightly.
// The search turns each match by them and keeps the pose that scores best, so that a part is not
// returned in a near-symmetric pose that the coarse levels could not tell from the right one.
// And the periods of a repeating pattern: shifts that map the model almost onto itself, which the
// automatic pyramid keeps beyond the reach of its top level, or, where level 0 repeats less well
// than its top level, the search tracks.

#include <vector>

#include <opencv2/core.hpp>

#include "algorithms/geometry/pose2d.hpp"

namespace facet {

struct ShapePoint;
struct ShapeLevel;

struct ModelSymmetry {
  double angle = 0.0;  // radians, the rotation that maps the model (almost) onto itself
  cv::Point2d centre;  // model coordinates, pixels: the centre of that rotation
  double score = 0.0;  // 0..1: share of the model's points that land on a point of like direction
};

// Rotations other than the identity whose self-similarity reaches `minScore`, best first, at
// most `maxCount`. `points` are the model's level-0 points; `angleStep` their search step.
std::vector<ModelSymmetry> findModelSymmetries(const std::vector<ShapePoint>& points,
                                               double angleStep, double minScore = 0.6,
                                               int maxCount = 3);

// Whether every turn (from a few `angleStep`s to a half turn) about the points' centroid maps
// them onto themselves with at least `minScore`, as a disc or a ring does: such a model's score is
// flat in angle, and its near-symmetries (findModelSymmetries) are just some of its turns.
bool mapsOntoItselfAtEveryTurn(const std::vector<ShapePoint>& points, double angleStep,
                               double minScore = 0.6);

// The near-symmetries a search must try for a model with these pyramid levels (level 0 first):
// those of level 0, and those of the top level, where the search starts and sees the part
// coarsest. A rectangular part with an off-centre feature is no symmetry on level 0 (its turn
// scores 0.7) but may be one on the top level, which then keeps the turned pose and loses the
// right one; such turns are located on level 0's points (the best turn within a top-level step).
std::vector<ModelSymmetry> findSearchSymmetries(const std::vector<ShapeLevel>& levels);

// A translation that maps the model almost onto itself: a period of a repeating pattern (a patch
// of a chessboard, a grid). Beyond the template the pattern often goes on, so a shifted
// pose is judged by the points that stay within the model's extent.
struct ModelPeriod {
  cv::Point2d shift;   // model coordinates, level-0 pixels
  double score = 0.0;  // 0..1: share of those points that land on a point of like direction
};

// The periods of a model with these pyramid levels (level 0 first) that its top level cannot
// tell apart: those that may put a shifted pose within `topReach` pixels of the top level, where
// the search keeps one maximum of the score over position among several that close
// (response_map_search.hpp) and a neighbouring period's pose may outscore the part's. Shifts
// under a pixel of the top level are not periods (the levels below look that far around each
// candidate), nor are slides along a straight edge (the shift's half must score less than half
// as much). Self-similarity as findModelSymmetries'. Best first, at most `maxCount`.
// `minScore`: the search trusts the top level's scores to within a factor of 0.7 (it keeps
// candidates from 0.7 x the minimum score there); a shifted pose that keeps less of the pattern
// than that does not rival the part's (a row of pins, 0.63: the body does not repeat).
// `levelZeroShare`: level 0's points need only this share of `minScore` (the top level's bar is
// `minScore` as it stands); see findTrackedPeriods.
std::vector<ModelPeriod> findSearchPeriods(const std::vector<ShapeLevel>& levels, int topReach,
                                           double minScore = 0.7, int maxCount = 4,
                                           double levelZeroShare = 1.0);

// The periods the search tracks beside each top-level candidate (find_shape_model.cpp): those the
// top level may not tell from the part's pose, though level 0 does not repeat well enough for the
// automatic pyramid to refuse the depth. A chessboard photographed at a slant keeps 0.63-0.68 of
// level 0's points under one period (the squares' spacing changes across the patch), while its
// top level, where the slant is gone, repeats at 0.72-0.86; a neighbouring square's pose two
// pixels away outscored the part's there (0.937 against 0.927) and the part (0.998) was missed.
// Refusing such depths cost a package with rows of pins (which repeat; its body does not) two of
// four levels and 22 times its search time. Level 0 is held to the share of the bar the search
// trusts a top-level score to (kTopFactor): enough to show the shift is a period of the pattern.
// Each period's opposite is among them.
std::vector<ModelPeriod> findTrackedPeriods(const std::vector<ShapeLevel>& levels);

// The pose that shows the model turned by `symmetry` where `pose` shows it: pose o S with
// S(p) = c + R(a) (p - c).
Pose2D turnedBy(const Pose2D& pose, const ModelSymmetry& symmetry);

}  // namespace facet
