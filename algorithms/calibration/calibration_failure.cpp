#include "algorithms/calibration/calibration_failure.hpp"

namespace facet {

std::string_view toString(CalibrationFailure failure) {
  switch (failure) {
    case CalibrationFailure::None:
      return "";
    case CalibrationFailure::PatternNotFound:
      return "pattern_not_found";
    case CalibrationFailure::TooFewViews:
      return "too_few_views";
    case CalibrationFailure::CoverageTooSmall:
      return "coverage_too_small";
    case CalibrationFailure::RmsTooLarge:
      return "rms_too_large";
  }
  return "";
}

}  // namespace facet
