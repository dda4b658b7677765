#pragma once
// Drawings of test parts in model coordinates (relative to the part's reference point), and
// placing them into a scene at a pose (see algorithms/geometry/pose2d.hpp for the convention).

#include <vector>

#include <opencv2/core.hpp>

#include "algorithms/geometry/pose2d.hpp"
#include "tests/support/scene/scene.hpp"

namespace facet::scene {

struct PartDrawing {
  // Painted in order: "object" primitives in the part's grey, "hole" primitives in the
  // background grey on top of them.
  std::vector<Primitive> primitives;
  cv::Size templateSize;  // a template image that holds the part with a margin
};

// An asymmetric bracket of about 130 x 100 px: an L-shaped plate with a chamfered corner and three
// holes of different sizes. No rotation maps it onto itself.
PartDrawing bracketPart();

// Paints the part at `pose` (q = t + s R(a) p). Object primitives get `partGrey`, holes
// `holeGrey`. Returns the axis-aligned bounding box of the placed part.
cv::Rect2d placePart(Scene& scene, const PartDrawing& part, const Pose2D& pose, double partGrey,
                     double holeGrey);

// A scene of exactly the template's size with the part at the template's reference point
// ((w-1)/2, (h-1)/2), angle 0, scale 1.
Scene templateScene(const PartDrawing& part, SceneSpec spec, double partGrey);

}  // namespace facet::scene
