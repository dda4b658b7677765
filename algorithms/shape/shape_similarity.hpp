#pragma once
// Steger's similarity measure (internal to facet_shape): the mean normalised dot product of the
// model's gradient directions, turned into the image, and the image's gradient directions.

#include <cstdint>
#include <vector>

#include <opencv2/core.hpp>

#include "algorithms/geometry/pose2d.hpp"
#include "algorithms/shape/find_shape_model.hpp"
#include "algorithms/shape/shape_model.hpp"

namespace facet::shape_detail {

// Model points turned and scaled into the image: integer offsets from the reference point and
// turned directions.
struct PosedPoints {
  std::vector<cv::Point> offsets;       // rounded s R(a) p, pixels of the level
  std::vector<cv::Point2f> directions;  // R(a) d
};

PosedPoints posePoints(const std::vector<ShapePoint>& points, double angle, double scale);

// The similarity at an integer position of a direction field (CV_8SC2, DirectionField), with
// early termination: after j of n points the pose is abandoned when the partial mean falls below a
// bound between the safe one (every remaining point adds the most a point can, greediness 0) and
// the greedy one (the remaining points match at exactly minScore, greediness 1). Returns the score,
// or -1 if abandoned. With `spread` > 0 each point inside the image takes the best direction within
// `spread` pixels in x and y (FindParams::maxDeformation); not with Polarity::IgnoreGlobal.
double scorePose(const cv::Mat& field, const PosedPoints& posed, cv::Point at, Polarity polarity,
                 double minScore, double greediness, int spread);

// The best scorePose (no early termination) over the 3x3 pixels around `at`: how well a level
// sees a pose whatever the phase of its pixel grid.
double bestScoreAround(const cv::Mat& field, const PosedPoints& posed, cv::Point at,
                       Polarity polarity, int spread);

// The similarity of the model's subpixel points at a subpixel pose, with the image's directions
// interpolated bilinearly: the score of a refined match. With `spread` > 0 each point takes the
// best of the directions at whole-pixel shifts of up to `spread` in x and y.
double refinedScore(const cv::Mat& field, const ShapeModel& model, const Pose2D& pose,
                    Polarity polarity, int spread);

// Which of the model's subpixel points have an image gradient (any direction above the field's
// contrast) within a pixel of where `pose` puts them. One entry per fine point, 1 = near one.
std::vector<std::uint8_t> pointsNearGradients(const cv::Mat& field, const ShapeModel& model,
                                              const Pose2D& pose);

}  // namespace facet::shape_detail
