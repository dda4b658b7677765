#pragma once
// Which edge estimator a shape model's least-squares refinement uses (shape_model.hpp,
// EdgeEstimator), chosen at training by a test whose answer is known: the template turned by a
// few known angles and shifted by a fraction of a pixel (resampled with Lanczos interpolation, as
// a part lands on the camera's pixel grid anywhere), searched with each estimator. The one that
// finds those poses again wins. A profile fit is the more precise estimator where edges are blurred
// steps, and such templates keep it; where contours lie a few pixels apart or the edges are not
// steps (shiny, textured parts), the fit takes in its neighbours and the poses drift by tenths of a
// pixel.

#include <vector>

#include <opencv2/core.hpp>

#include "algorithms/shape/shape_model.hpp"

namespace facet {

struct EdgeEstimatorChoice {
  EdgeEstimator chosen = EdgeEstimator::ProfileFit;
  std::vector<EdgeEstimatorTrial> trials;  // one per estimator tried
};

// Tries `candidates` (models trained from the same template and parameters, one per estimator;
// each model's edgeEstimator says which) on turned copies of `templateImage` (the trained region,
// the model's reference point in its pixels; where it is a region of a larger image, the copies
// show that image around it) and returns the estimator that reproduces the poses best: the lower
// mean error, copy by copy (the profile fit on a tie). Candidates whose reference points differ
// are refused (std::invalid_argument): each turned copy serves them all.
EdgeEstimatorChoice chooseEdgeEstimator(const cv::Mat& templateImage,
                                        const std::vector<const ShapeModel*>& candidates);

}  // namespace facet
