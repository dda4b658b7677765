#pragma once
// Near-symmetries of a shape model: rotations about the centre of its edge points that map the
// model (almost) onto itself, such as the quarter turns of a cross whose arms differ slightly.
// The search turns each match by them and keeps the pose that scores best, so that a part is not
// returned in a near-symmetric pose that the coarse levels could not tell from the right one.

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

// The pose that shows the model turned by `symmetry` where `pose` shows it: pose o S with
// S(p) = c + R(a) (p - c).
Pose2D turnedBy(const Pose2D& pose, const ModelSymmetry& symmetry);

}  // namespace facet
