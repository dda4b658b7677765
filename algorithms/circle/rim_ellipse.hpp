#pragma once
// A round rim that the image shows as an ellipse: a hole or a disc on a plane the camera views at
// a tilt (a circle tilted by t degrees is an ellipse with axes ratio cos t), off the lens's axis,
// or an oval part.
//
// The circle measurement's robust fit keeps the edge points within 0.5 px of its circle. On an
// elliptic rim whose axes differ by more than that band it keeps the arcs one circle matches,
// on one side, and its centre moves along the minor axis: on a 29 px hole viewed at 20 degrees
// (semi-axes 2.3 px apart) 2.4 px off, while an ellipse through all the rim's points is within
// 0.02 px of the true ellipse's centre. Here: the ellipse, its distance and normal, the map that
// makes it a circle, and the tests that tell it from a circle (the second harmonic of the
// circle's residuals, the F statistic of the ellipse against the circle); circle_measure.cpp
// decides with them.

#include <optional>
#include <vector>

#include <Eigen/Core>
#include <opencv2/core.hpp>

#include "algorithms/circle/circle_fit.hpp"

namespace facet::rim_ellipse {

struct Ellipse {
  Eigen::Vector2d centre;
  double major = 0.0, minor = 0.0;    // semi-axes, pixels (major >= minor)
  Eigen::Vector2d axis = {1.0, 0.0};  // unit direction of the major axis (x right, y down)

  // The radius of the circle of equal area, sqrt(major * minor).
  [[nodiscard]] double meanRadius() const;
  // The linear map (area-preserving, symmetric) that takes the ellipse about its centre to the
  // circle of radius meanRadius(): offsets from the centre map by it.
  [[nodiscard]] cv::Matx22d toCircle() const;
};

// The ellipse whose map to the circle is exp(S) toCircle() (made symmetric again: a rotation
// after it leaves every mapped distance as it is), S = [[a, c], [c, -a]]: `e` reshaped by a
// step of the grey-value fit (CircleProfileFit::shapeStep). Same centre and mean radius.
Ellipse reshaped(const Ellipse& e, double a, double c);

// The (a, c) of exp([[a, c], [c, -a]]) = e.toCircle(): how far the ellipse is from round, in
// the parameters of reshaped (zero for a circle).
cv::Vec2d stretchOf(const Ellipse& e);

// Signed distance of p from the ellipse, positive outside; first order in the distance (the
// ellipse's implicit function over its gradient), exact on the axes.
double residual(const Ellipse& e, const Eigen::Vector2d& p);

// The ellipse's outward unit normal at the point of it nearest p (to first order).
Eigen::Vector2d outwardNormal(const Ellipse& e, const Eigen::Vector2d& p);

// Chi-square (2 degrees of freedom) of the second harmonic, cos 2phi and sin 2phi around the
// circle's centre, in the residuals of the circle's points: how clearly they say the rim is not
// a circle but an ellipse. Chance alone exceeds 27.6 once in a million measurements.
double secondHarmonicChiSquare(const std::vector<Eigen::Vector2d>& pts,
                               const circle_fit::Circle& circle);

struct Fit {
  Ellipse ellipse;
  std::vector<Eigen::Vector2d> inliers;  // rim points within the threshold of the ellipse
  double rms = 0.0;                      // of their residuals to the ellipse, pixels
  // F statistic of the ellipse against the circle fitted to the same inliers (2 and n - 5
  // degrees of freedom): beyond about 14 chance alone explains the improvement once in a million.
  double fStatistic = 0.0;
};

// The ellipse of a rim, grown from the points a circle fit kept (`seed`): fitted to them
// (the direct least-squares ellipse fit), then to every point of `pts` within `threshold`
// of it whose outward gradient direction `normals` (unit vectors) lies within acos(`cosTolerance`)
// of the ellipse's normal, until those points stop changing. Nothing when the fit is not a
// finite ellipse or keeps fewer than 6 points.
std::optional<Fit> fitRimEllipse(const std::vector<Eigen::Vector2d>& pts,
                                 const std::vector<Eigen::Vector2d>& normals,
                                 const std::vector<Eigen::Vector2d>& seed, double threshold,
                                 double cosTolerance);

// A seed for fitRimEllipse where no circle's points make one: the points of `pts` (as there)
// that agree with the best of ellipses through random sets of six of them (RANSAC, adaptive, at
// most 300 sets). A circle locked onto arcs of a partly hidden elliptic rim, or all the rim's
// candidates with an occluder's border among them, can grow into an ellipse that holds only
// part of the rim; the consensus of sampled ellipses starts on the whole visible rim. Empty
// when no sampled ellipse takes in six points.
std::vector<Eigen::Vector2d> ellipseConsensus(const std::vector<Eigen::Vector2d>& pts,
                                              const std::vector<Eigen::Vector2d>& normals,
                                              double threshold, double cosTolerance);

}  // namespace facet::rim_ellipse
