#pragma once
// Finding a shape model in an image: exhaustive search on the top pyramid level, candidates tracked
// down the pyramid, non-maximum suppression by overlap, then subpixel refinement (Steger 2002).
//
// Score: the mean, over the model's points, of the normalised dot product of the model's gradient
// direction (rotated into the image) and the image's gradient direction at the point. It lies in
// [0, 1] and reads as "visible fraction of the model"; points outside the image or on gradients
// weaker than the model's minContrast count as 0.

#include <numbers>
#include <vector>

#include <opencv2/core.hpp>

#include "algorithms/geometry/pose2d.hpp"
#include "algorithms/shape/shape_model.hpp"

namespace facet {

enum class Polarity {
  Use,           // the part's contrast has the trained sign everywhere (dark/light as trained)
  IgnoreGlobal,  // the whole part may appear with inverted contrast
  IgnoreLocal,   // the contrast may invert anywhere along the contour (e.g. varying background)
};

enum class SubpixelMode {
  None,           // integer position on level 0, angle and scale on the level-0 step grid
  Interpolation,  // parabola through the scores around the maximum in x, y, angle (and scale)
  LeastSquares,   // ICP of the model's subpixel edges against the image's Facet-model subpixel
                  // edges (point-to-line), in position, angle and (with a scale range) scale
};

inline constexpr double kMaxScaleTolerance = 0.1;
inline constexpr int kMaxDeformation = 8;

struct FindParams {
  // Lowest score a match may have, in (0, 1]. Default 0.7.
  double minScore = 0.7;
  // Number of matches to return, best first; 0 = all above minScore. Default 1.
  int numMatches = 1;
  // Largest allowed overlap of two matches' oriented bounding boxes, as a fraction (0..1) of the
  // smaller box; of two matches that overlap more, the better one is kept. Default 0.5.
  double maxOverlap = 0.5;
  // Early termination when scoring a pose on the levels below the top, 0..1: 0 = safe (abandon a
  // pose only when it cannot reach minScore even if every remaining point matched perfectly),
  // 1 = fastest (abandon it as soon as the points so far match at less than minScore). Values
  // above 0 can miss clear parts on real photographs, where a part's points match unevenly (a
  // part scoring 0.9 was lost at 0.9). Default 0 (safe).
  double greediness = 0.0;
  // Angle range searched, radians: [angleStart, angleStart + angleExtent], intersected with the
  // model's trained range. Default: full circle.
  double angleStart = -std::numbers::pi;
  double angleExtent = 2.0 * std::numbers::pi;
  // Scale range searched (unitless), intersected with the model's trained range.
  // 0 = the model's trained bound (default: the model's whole trained range).
  double scaleMin = 0.0;
  double scaleMax = 0.0;
  // Contrast polarity. Default Use.
  Polarity polarity = Polarity::Use;
  // Subpixel refinement of each match. Default LeastSquares.
  SubpixelMode subpixel = SubpixelMode::LeastSquares;
  // Least squares with a model of fixed scale: the refinement may also adjust the scale by up to
  // this relative amount (real parts and lenses differ from the template by a percent or so; a
  // fixed scale would pull the position towards one side). Where the free scale may have been
  // pulled (its fit is not exact), the part is also refined at the model's scale, and where that
  // is not exact either, with the scale free on the points that have image gradients near them
  // at the start only; the fit that lays more of the model on edges is kept (an occluder's border
  // can stand in for a hidden edge at a scale a percent or two off). The match reports the scale
  // it kept.
  // 0 = keep the scale fixed; at most kMaxScaleTolerance (a part 10% off its template is another
  // part, or wants a model with a scale range). Default 0.02.
  double refineScaleTolerance = 0.02;
  // Tolerance for parts whose contour differs from the model's by up to this many pixels in x and
  // y (a moulded or stamped part, a lens window set off-centre in its housing): each model point
  // matches the best image direction within that distance, on every pyramid level (divided by the
  // level's factor, rounded down) and in the score, which then reads "share of the model seen
  // within maxDeformation pixels"; the pose is where the rigid score peaks nearby, refined by least
  // squares on the whole contour as it is. Scores rise, clutter's too: raise minScore with it.
  // 0 = rigid. 0..kMaxDeformation; not with Polarity::IgnoreGlobal (use IgnoreLocal). A search
  // with 1 px costs about 3x the rigid one (a 1628x1236 photograph of 36 parts). Default 0.
  int maxDeformation = 0;
  // Number of pyramid levels used, 0 = all of the model's. Fewer levels = slower, more robust.
  int numLevels = 0;
  // Parallelism on OpenCV's worker pool: stripes of the top-level search (1..8), and, when > 1,
  // the candidates tracked down the pyramid in parallel. The matches do not depend on it.
  // Default 2.
  int threads = 2;
};

struct ShapeMatch {
  double x = 0.0;  // reference point in the image, pixels
  double y = 0.0;
  double angle = 0.0;  // radians, counter-clockwise on screen (wrapped to (-pi, pi])
  double scale = 1.0;  // unitless
  // 0..1, see above. With subpixel refinement: the similarity of the model's subpixel points
  // (image directions interpolated bilinearly) at the refined pose, or at the search's
  // interpolated pose where that is higher (the refinement may give up a little of it to fit the
  // whole part, refinement_choice.hpp); without: on the level-0 grid.
  double score = 0.0;
  // The model's subpixel edge points placed into the image at this pose, for overlays.
  std::vector<cv::Point2d> contour;
  // Least squares only: RMS point-to-line distance of the matched points, pixels (0 otherwise).
  double residual = 0.0;

  [[nodiscard]] Pose2D pose() const { return {x, y, angle, scale}; }
};

// Finds up to params.numMatches instances of `model` in an 8-bit or 16-bit single-channel image,
// best score first. An empty image gives no matches. Throws std::invalid_argument for an empty
// model, a multi-channel image or parameters out of range.
std::vector<ShapeMatch> findShapeModel(const cv::Mat& image, const ShapeModel& model,
                                       const FindParams& params = {});

}  // namespace facet
