#pragma once
// Least-squares refinement of a match (internal to facet_shape): ICP of the model's subpixel
// points against the image's Facet-model subpixel edges, minimising point-to-line distances
// along the image edge normals in position, angle and optionally scale.

#include <cstdint>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "algorithms/edges/subpixel_edges.hpp"
#include "algorithms/geometry/pose2d.hpp"
#include "algorithms/shape/find_shape_model.hpp"
#include "algorithms/shape/shape_model.hpp"
#include "algorithms/status/status.hpp"

namespace facet::shape_detail {

// Internal to the search, never reported: no name for logs.
enum class RefinementFailure {
  None,
  TooFewCorrespondences,  // too few model points met image edges; the pose is the start pose
};

// The Tukey cut-off of the refinement's last steps is 4.685 robust sigmas of the pairs' distances,
// clamped to [kMinCutoff, kMaxCutoff] pixels.
inline constexpr double kMinCutoff = 0.15;
inline constexpr double kMaxCutoff = 1.5;
// A fit whose cut-off ends at or below this lays the model's points on edges within a median of
// 0.04 px: what a fit onto a part's own contour reaches on a sharp image (0.15-0.24 px on rendered
// scenes, occluded or not). Fits locked onto texture or a neighbour's edges end at 1.2-1.5 px (a
// photograph of LEDs); so do correct fits on photographs (0.5-1.5 px), which are therefore never
// judged exact.
inline constexpr double kExactFitCutoff = 0.3;

struct Refined {
  Pose2D pose;
  double residual = 0.0;  // weighted RMS point-to-line distance, pixels
  Status<RefinementFailure> status;
  // How well the model's points lie on image edges (each weighted by its distance across the
  // edge, 1 on it, 0 from a pixel away) at the refined pose and at the start: a refinement
  // that lowers it has made the pose worse.
  double support = 0.0;
  double startSupport = 0.0;
  // The distance across an edge beyond which a point no longer counted in the last step, pixels:
  // it follows the fit's own residuals, so it tells how closely the fit lays the model on edges.
  double cutoff = 0.0;
  // With the scale free: the standard error of the relative scale, from the last step's normal
  // equations and residual (0 otherwise).
  double scaleSigma = 0.0;
  // Polarity IgnoreGlobal: the sign of the part's contrast the first pass found (1 or -1).
  double contrastSign = 1.0;
  [[nodiscard]] bool exact() const { return status.ok() && cutoff <= kExactFitCutoff; }
};

// The image's subpixel edges inside one part's region, detected once for the refinements tried
// there: from each of the part's alternative poses (near-symmetric turns, other candidates on it),
// with the scale free and at the model's scale. One detection for all of them also lets them be
// compared on the same edges.
class LeastSquaresRefinement {
 public:
  // `roi`: image pixels, clipped to the image. `starts`: the poses the refinements start from;
  // `scaleFreedom`: the largest relative scale change they may make. Only the edges near the
  // model's contour placed at one of the starts get the profile fit (contourBand).
  LeastSquaresRefinement(const cv::Mat& image, const ShapeModel& model, cv::Rect roi,
                         Polarity polarity, const std::vector<Pose2D>& starts, double scaleFreedom);

  // `visible`: one entry per fine point, 0 for a point that takes no part; empty: every point.
  Refined refine(Pose2D start, bool withScale, const std::vector<std::uint8_t>& visible = {}) const;

  // How well the model's points lie on edges at the fit's pose, each counted by Tukey's biweight
  // of its distance across the edge: 1 on it, 0 from `cutoff` pixels away.
  double support(const Refined& fit, double cutoff) const;

 private:
  struct Pair {
    Eigen::Vector4d J;
    double r;
  };
  // The roi's pixels near the model's contour placed at any of `starts` (CV_8U, non-zero), see
  // the .cpp; empty where that is most of the roi.
  [[nodiscard]] cv::Mat contourBand(const std::vector<Pose2D>& starts, double scaleFreedom) const;
  // Each model point placed at `at` paired with the nearest direction-agreeing edge point within
  // `radius` pixels; returns the sum of the pairs' direction agreements (the global polarity).
  double correspond(const Pose2D& at, int radius, bool anySign, double sign,
                    std::vector<Pair>& pairs, const std::vector<std::uint8_t>& visible = {}) const;
  template <int Radius>
  double correspondWithin(const Pose2D& at, bool anySign, double sign, std::vector<Pair>& pairs,
                          const std::vector<std::uint8_t>& visible) const;
  double support(const Pose2D& at, double sign, double cutoff) const;

  const ShapeModel& model_;
  Polarity polarity_;
  cv::Rect roi_;
  EdgeContours edges_;
  // Index of the strongest edge point in each pixel of the region, -1 for none; framed by
  // kCellBorder empty cells on every side, so that a correspondence window never needs clipping.
  static constexpr int kCellBorder = 6;
  cv::Mat cell_;
};

}  // namespace facet::shape_detail
