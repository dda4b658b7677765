#pragma once
// `facet circle --calibration FILE`: the measured circle in the calibration's measuring plane.

#include <nlohmann/json.hpp>

#include "algorithms/circle/circle_measure.hpp"
#include "service/cli/measuring_plane.hpp"

namespace facet::cli {

// {"x_mm", "y_mm", "diameter_mm", "calibration"}: with a lens model and a plane the rim is
// mapped into the plane and the circle fitted there; with mm_per_pixel alone the pixel values
// are scaled.
nlohmann::json worldCircle(const MeasuringPlane& plane, const CircleMeasurement& measurement);

}  // namespace facet::cli
