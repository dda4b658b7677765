#pragma once
// How far a fitted transform may be off where it is used, from the pairs it was fitted to. A
// homography is fixed by its pairs only as far as they spread: fitted to pairs on a strip of the
// view (the one textured band of a dark part), it is exact along the strip and may put the far
// corners of the view tens of pixels off, its pairs agreeing with it to a fraction of a pixel.
// First-order propagation of the pairs' noise (Hartley and Zisserman, Multiple View Geometry,
// 5.2): the covariance of the transform's parameters from the normal matrix of its transfer
// errors, then that of each mapped point from its Jacobian with respect to them.

#include <vector>

#include <opencv2/core.hpp>

#include "algorithms/registration/transform_fit.hpp"

namespace facet {

// The largest standard deviation (pixels, along its worst direction) of where `H`, a transform
// of the family `model` (a similarity [a b tx; -b a ty], an affine map, a homography with
// H(2,2) = 1), maps any of `points`, given the pairs (src[i], dst[i]) it was fitted to and the
// covariance of each pair's transfer error (pixels^2; a pair located sharply across an edge and
// loosely along it fixes H across the edge only). Infinity when the pairs do not fix H (too few,
// or all but collinear).
double mappedPointUncertainty(TransformModel model, const cv::Matx33d& H,
                              const std::vector<cv::Point2d>& src,
                              const std::vector<cv::Point2d>& dst,
                              const std::vector<cv::Matx22d>& errorCovariance,
                              const std::vector<cv::Point2d>& points);

// How much more the pairs' errors weigh together than apart because neighbouring pairs share
// them (pairs re-matched from overlapping patches see the same pixels; pairs on one edge slide
// along it together): Kish's design effect 1 + m rho, m the mean number of other pairs within
// `radius` (pixels, source side) of a pair, rho the mean correlation of their `residual`s (the
// transfer errors about the fitted transform). At least 1; the pairs' covariances are to be
// multiplied by it. Without it, 69 pairs along a drawing's edges stated 0.8 px where the view's
// corners were 3-6 px off.
double sharedErrorFactor(const std::vector<cv::Point2d>& src,
                         const std::vector<cv::Point2d>& residual, double radius);

// The same with every pair's error a 2D Gaussian of sigma `noise` (pixels) in each coordinate.
double mappedPointUncertainty(TransformModel model, const cv::Matx33d& H,
                              const std::vector<cv::Point2d>& src,
                              const std::vector<cv::Point2d>& dst, double noise,
                              const std::vector<cv::Point2d>& points);

}  // namespace facet
