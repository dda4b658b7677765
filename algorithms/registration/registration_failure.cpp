#include "algorithms/registration/registration_failure.hpp"

namespace facet {

std::string_view toString(RegistrationFailure failure) {
  switch (failure) {
    case RegistrationFailure::None:
      return "";
    case RegistrationFailure::EmptyImage:
      return "empty_image";
    case RegistrationFailure::BlankImage:
      return "blank_image";
    case RegistrationFailure::TooFewCorners:
      return "too_few_corners";
    case RegistrationFailure::TooFewMatches:
      return "too_few_matches";
    case RegistrationFailure::TooFewInliers:
      return "too_few_inliers";
    case RegistrationFailure::DegenerateTransform:
      return "degenerate_transform";
    case RegistrationFailure::UndeterminedTransform:
      return "undetermined_transform";
    case RegistrationFailure::TooFewFiducials:
      return "too_few_fiducials";
  }
  return "";
}

}  // namespace facet
