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

// The pose that shows the model turned by `symmetry` where `pose` shows it: pose o S with
// S(p) = c + R(a) (p - c).
Pose2D turnedBy(const Pose2D& pose, const ModelSymmetry& symmetry);

}  // namespace facet
