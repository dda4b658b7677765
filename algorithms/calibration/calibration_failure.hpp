#pragma once
// Why a camera calibration was refused (CameraCalibration::status), a view left out
// (ViewFit::status), or the measuring plane not found (estimatePlanePose).

#include <string_view>

namespace facet {

enum class CalibrationFailure {
  None,
  PatternNotFound,   // the plate's pattern was not found in the view, or not precisely
  TooFewViews,       // fewer views with the pattern found than CalibrationOptions::minViews
  CoverageTooSmall,  // the views cover less of the image than CalibrationOptions::minCoverage
  RmsTooLarge,       // the reprojection error is above CalibrationOptions::maxRmsPx
};

// snake_case name for logs ("too_few_views", ...); "" for None.
[[nodiscard]] std::string_view toString(CalibrationFailure failure);

}  // namespace facet
