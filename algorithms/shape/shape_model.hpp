#pragma once
// A shape model: the edge points of a template, with their gradient directions, on every level of
// an image pyramid (Steger 2002, "Occlusion, clutter, and illumination invariant object
// recognition"). createShapeModel() trains it from a template image; findShapeModel()
// (find_shape_model.hpp) searches it; shape_model_file.hpp saves and loads it.
//
// Model coordinates are pixels relative to the reference point, x right, y down. A match's pose
// maps them into the image as q = t + s R(a) p (algorithms/geometry/pose2d.hpp).

#include <numbers>
#include <optional>
#include <stdexcept>
#include <vector>

#include <opencv2/core.hpp>

#include "algorithms/geometry/pose2d.hpp"
#include "algorithms/shape/model_symmetry.hpp"

namespace facet {

// How the least-squares refinement locates subpixel edges, in the template and in searched images.
enum class EdgeEstimator {
  // The facet zero crossing refined by a blurred-step profile fit (edge_profile_fit.hpp): the
  // most precise where the part's edges are blurred straight steps (machined and printed parts).
  ProfileFit,
  // The cubic facet model's zero crossing alone: steadier where edges are not steps (shiny,
  // textured parts whose contours lie a few pixels apart), where a profile fit takes in the
  // neighbouring contours.
  FacetZeroCrossing,
};

// The estimator's name in commands, JSON and benchmark tables: "profile" or "zero-crossing".
const char* edgeEstimatorName(EdgeEstimator estimator);

// One estimator's result in the training test that chooses it (edge_estimator_choice.hpp).
struct EdgeEstimatorTrial {
  EdgeEstimator estimator = EdgeEstimator::ProfileFit;
  // RMS, over the template's turned copies, of how far the found pose puts the model's subpixel
  // points from where the true pose puts them, pixels; +infinity when a copy was not found.
  double poseError = 0.0;
};

// One depth of the automatic pyramid tried at training.
struct PyramidTrial {
  int levels = 0;
  int copiesLost = 0;  // of the template's turned, shifted copies (pyramid_depth_check.hpp)
  // Set where the depth was refused because the part's pattern repeats too closely for its top
  // level (findSearchPeriods, model_symmetry.hpp): the best-scoring such period. No copies were
  // searched then.
  std::optional<ModelPeriod> period;
};

struct ShapeModelParams {
  // Region of the template image that holds the part, image pixels; empty = the whole image.
  // The image around the region is read too: every level sees near the region's border what a
  // search image's pyramid sees there, but only the region's pixels give model points.
  cv::Rect roi;
  // Optional 8-bit mask of the template's size (or of the roi's size when roi is set): only
  // edges on non-zero pixels belong to the model. Empty = every pixel.
  cv::Mat mask;
  // Reference point in template pixels (the point whose image position a match reports).
  // Default: the centre of the region, ((w-1)/2, (h-1)/2) of the roi or the whole template.
  std::optional<cv::Point2d> referencePoint;

  // Number of pyramid levels, >= 1. 0 = automatic: each level halves the image, and the search
  // on the top level costs about 1/16 of the one below it (a quarter of the positions, half the
  // angles, half the points), so the model takes every level that still holds the part: at
  // least 24 edge pixels and a radius of at least 5 pixels (angle step below 12 degrees) on the
  // top level, whatever the template's width. At most 6 levels. Then fewer while the part's
  // pattern repeats within a few pixels of the top level (a chessboard, a grid: the top level
  // cannot keep the part's pose beside a period's; findSearchPeriods), and while the
  // deepest pyramid loses turned, shifted copies of the template that a shallower one finds,
  // or would lose them at the minimum score (pyramid_depth_check.hpp; ShapeModel::pyramidTrials).
  int numLevels = 0;

  // Angle range searched, radians: [angleStart, angleStart + angleExtent]. Default: full circle.
  // An extent >= 2 pi means "any angle".
  double angleStart = -std::numbers::pi;
  double angleExtent = 2.0 * std::numbers::pi;
  // Angle step on level 0, radians. 0 = automatic, about atan(1 / R) for a model of radius R
  // (the outermost point then moves by at most half a pixel between steps). Doubles per level.
  double angleStep = 0.0;

  // Scale range searched (unitless, 1 = template size): [scaleMin, scaleMax], 0 < min <= max.
  double scaleMin = 1.0;
  double scaleMax = 1.0;
  // Scale step on level 0, unitless. 0 = automatic, about 1 / R. Doubles per level.
  double scaleStep = 0.0;

  // Hysteresis thresholds for the template's edges, grey levels per pixel (8-bit scale).
  // Missing = automatic from the template's gradient histogram.
  std::optional<double> contrastLow;
  std::optional<double> contrastHigh;
  // Image gradients weaker than this (grey levels per pixel, 8-bit scale) are treated as noise
  // and contribute nothing to the score during the search. Default 5.
  double minContrast = 5.0;
  // Edge components (8-connected edge pixels after hysteresis) with fewer pixels than this on
  // level 0 are left out of the model (on level l, this divided by 2^l): the contours of specks,
  // dust and the texture of one sample, which another sample of the part does not have, and which
  // would lower its score. 0 or 1 = keep every component. Missing = automatic: 10 pixels (the
  // contour of a dot about 3 px across), unless the short components hold half of the template's
  // edge pixels or more (a pattern of small features: they are the part, and all are kept).
  std::optional<int> minComponentSize;
  // Most points kept per pyramid level; larger models are thinned evenly along their edges.
  // Default 800 (level 0), 0 = no thinning. Upper levels keep at most 250 (top-level SIMD sums).
  int maxPoints = 800;
  // Edge estimator of the least-squares refinement. Unset (default): chosen at training as the
  // one that finds the template's own pose again on copies of it turned by known angles
  // (edge_estimator_choice.hpp).
  std::optional<EdgeEstimator> edgeEstimator;
};

// One model point: position relative to the reference point (pixels of its pyramid level) and the
// unit gradient direction (dark -> light) in model axes.
struct ShapePoint {
  cv::Point2f position;
  cv::Point2f direction;
};

struct ShapeLevel {
  std::vector<ShapePoint> points;
  double angleStep = 0.0;  // radians, search step on this level
  double scaleStep = 0.0;  // unitless, search step on this level (0 when the scale is fixed)
};

struct ShapeModel {
  // Level 0 first; level l has the template downsampled by 2^l (cv::pyrDown).
  std::vector<ShapeLevel> levels;
  // Subpixel (Facet-model) edge points of the template on level 0, relative to the reference
  // point; the least-squares refinement matches these against the image's subpixel edges.
  std::vector<ShapePoint> finePoints;
  // How finePoints were found, and how the refinement finds the image's edges.
  EdgeEstimator edgeEstimator = EdgeEstimator::ProfileFit;
  // The training test that chose it (empty when it was given, or the model was loaded).
  std::vector<EdgeEstimatorTrial> edgeEstimatorTrials;
  // The automatic pyramid's tests, deepest first: the depths refused for a period of the part's
  // pattern, then the copies of the template each depth searched lost (pyramid_depth_check.hpp).
  // Empty when the levels were given, the edges allow one level only, or the model was loaded.
  std::vector<PyramidTrial> pyramidTrials;

  cv::Size templateSize;                  // size of the trained region, pixels
  cv::Point2d referencePoint;             // in the trained region's pixels
  double angleStart = -std::numbers::pi;  // radians
  double angleExtent = 2.0 * std::numbers::pi;
  double scaleMin = 1.0;
  double scaleMax = 1.0;
  double minContrast = 5.0;  // grey levels per pixel
  double contrastLow = 0.0;  // thresholds actually used for the template, grey levels per pixel
  double contrastHigh = 0.0;
  // Shortest edge component kept on level 0, pixels (ShapeModelParams::minComponentSize as
  // applied; 0 = all kept). Training only: 0 for a model loaded from a file.
  int minComponentSize = 0;
  // Rotations that map the model almost onto itself, on level 0 or on the top level
  // (findSearchSymmetries, model_symmetry.hpp; derived from the points when the model is
  // created, and kept in its file).
  std::vector<ModelSymmetry> symmetries;
  // Shifts that map the model almost onto itself within its top level's reach, which the search
  // tracks beside each top-level candidate (findTrackedPeriods, model_symmetry.hpp). Derived from
  // the points when the model is created, and kept in its file.
  std::vector<ModelPeriod> trackedPeriods;

  [[nodiscard]] bool empty() const { return levels.empty(); }
  [[nodiscard]] int numLevels() const { return static_cast<int>(levels.size()); }
  // Largest distance of a level-0 point from the reference point, pixels.
  [[nodiscard]] double radius() const;
  // How far pose `a` puts the subpixel points from where pose `b` puts them: RMS, pixels. The
  // error of a found pose over the whole part, which its angle and scale enter as well as its
  // place.
  [[nodiscard]] double pointsDistance(const Pose2D& a, const Pose2D& b) const;
};

// Thrown for templates that give no usable model (no edges, empty image, bad parameters).
struct ShapeModelError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// Trains a shape model from an 8-bit or 16-bit single-channel template image.
// Throws ShapeModelError when the template is empty, the parameters are out of range, or the
// template has too few edges (fewer than 8 points on level 0).
ShapeModel createShapeModel(const cv::Mat& templateImage, const ShapeModelParams& params = {});

}  // namespace facet
