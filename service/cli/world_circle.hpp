#pragma once
// `facet circle --calibration FILE`: the measured circle in the calibration's measuring plane.

#include <string>

#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>

#include "algorithms/circle/circle_measure.hpp"
#include "service/cli/measuring_plane.hpp"

namespace facet::cli {

// {"x_mm", "y_mm", "diameter_mm", "roundness_mm", "calibration"}: with a lens model and a plane
// the rim is measured in the plane (edge points and grey values, plane_circle.hpp; also "rms_mm",
// "coverage_deg", "grey_refined"), and a rim the image refused as a circle (an ellipse on a steep
// view) is judged there ("judged_in_plane": true; null with the reason in `refusal` when the
// plane refuses it too); with mm_per_pixel alone the pixel values are scaled (null when the image
// measurement failed).
nlohmann::json worldCircle(const MeasuringPlane& plane, const cv::Mat& image,
                           const CircleMeasurement& measurement, const CircleMeasureParams& params,
                           std::string& refusal);

}  // namespace facet::cli
