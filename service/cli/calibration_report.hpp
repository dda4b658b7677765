#pragma once
// The HTML page of `facet calibrate --report`: residual vectors over the field, per-view errors,
// the covered share of the image.

#include <string>

#include "algorithms/calibration/board_spec.hpp"
#include "algorithms/calibration/camera_calibration.hpp"
#include "config/calibration_file.hpp"

namespace facet::cli {

void writeCalibrationReport(const std::string& file, const BoardSpec& board, cv::Size imageSize,
                            const CameraCalibration& calibration,
                            const config::CalibrationData& data);

}  // namespace facet::cli
