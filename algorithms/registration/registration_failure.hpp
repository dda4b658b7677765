#pragma once
// Why an image could not be registered (RegistrationResult::status), or its fiducials not
// located (FiducialResult::status).

#include <string_view>

namespace facet {

enum class RegistrationFailure {
  None,
  EmptyImage,           // the reference or the image is empty
  BlankImage,           // the reference or the image is uniform: no corners
  TooFewCorners,        // fewer than 4 usable corners in either
  TooFewMatches,        // fewer consistent matches than the model and minInliers need
  TooFewInliers,        // the fit (or its confirmation by re-matching) has too few inliers
  DegenerateTransform,  // no non-degenerate transform fits the matches
  // the inliers fix the transform only near them: it may put points of the views' overlap farther
  // off than inlierThreshold (RegistrationResult::overlapUncertainty)
  UndeterminedTransform,
  TooFewFiducials,  // fewer than two distinct reference marks
};

// snake_case name for JSON and logs ("empty_image", "too_few_inliers", ...); "" for None.
[[nodiscard]] std::string_view toString(RegistrationFailure failure);

}  // namespace facet
