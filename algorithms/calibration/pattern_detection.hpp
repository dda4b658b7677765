#pragma once
// PatternDetection: where a calibration plate's points lie in one image.

#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "algorithms/calibration/board_spec.hpp"
#include "algorithms/calibration/calibration_failure.hpp"
#include "algorithms/status/status.hpp"

namespace facet {

struct PatternDetection {
  // Not found until a detector has found it; PatternNotFound with the reason for the user.
  Status<CalibrationFailure> status{CalibrationFailure::PatternNotFound, {}};
  std::vector<cv::Point2d> points;  // image pixels, in BoardSpec::platePoints() order
  // Boards with partial views (charuco): the index into BoardSpec::platePoints() of each point.
  // Empty: `points` holds every pattern point, in that order.
  std::vector<int> ids;
  std::string note;  // found, with a reservation for the engineer (empty: none)

  // The plate coordinates of `points`, one each.
  [[nodiscard]] std::vector<cv::Point3d> platePoints(const BoardSpec& board) const;
};

}  // namespace facet
