#pragma once
// PatternDetection: where a calibration plate's points lie in one image.

#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "algorithms/calibration/calibration_failure.hpp"
#include "algorithms/status/status.hpp"

namespace facet {

struct PatternDetection {
  // Not found until a detector has found it; PatternNotFound with the reason for the user.
  Status<CalibrationFailure> status{CalibrationFailure::PatternNotFound, {}};
  std::vector<cv::Point2d> points;  // image pixels, in BoardSpec::platePoints() order
  std::string note;                 // found, with a reservation for the engineer (empty: none)
};

}  // namespace facet
