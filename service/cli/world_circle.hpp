#pragma once
// `facet circle --calibration FILE`: the measured circle in the calibration's measuring plane.

#include <string>

#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>

#include "algorithms/circle/circle_measure.hpp"

namespace facet::cli {

// {"x_mm", "y_mm", "diameter_mm", "calibration"}: with a lens model and a plane the rim is
// mapped into the plane and the circle fitted there; with mm_per_pixel alone the pixel values
// are scaled ("calibration": "scale only, no lens model"). Throws InputError for an unusable
// calibration file (file:line:column) or one made for another image size.
// The same checks alone, before measuring: a broken calibration is bad input (exit 1) even when
// the circle would not be found.
void checkCalibrationFor(const std::string& calibrationFile, cv::Size imageSize);

nlohmann::json worldCircle(const std::string& calibrationFile, cv::Size imageSize,
                           const CircleMeasurement& measurement);

}  // namespace facet::cli
