#pragma once
// A located part's offset from its nominal place, as the check values x, y and angle of the
// steps that locate parts (align, shape, fiducials). With a lens model and a measuring plane the
// offset is measured there: x and y in mm along the plane's axes (the calibration plate's), the
// turn between the part's and the nominal x directions as the plane sees them. Pixels times one
// scale would ignore the lens and the view's tilt, which change the scale across the image.

#include <optional>

#include <opencv2/core.hpp>

#include "algorithms/calibration/world_mapping.hpp"
#include "service/engine/step_result.hpp"

namespace facet::service {

// The x and y checks' descriptions, in one wording for the steps that locate parts.
inline constexpr const char* kOffsetXDoc =
    "Offset of the found position from nominal along x (mm by default; with a lens model and a "
    "measuring plane, along the plane's x, measured there).";
inline constexpr const char* kOffsetYDoc =
    "Offset of the found position from nominal along y (mm by default; with a lens model and a "
    "measuring plane, along the plane's y, measured there).";

// Sets r.values x, y (pixels of the live image, or mm in the plane with lengthsInMm) and
// angle (degrees, counter-clockwise on screen) for a part found at `found` turned by
// `angleDeg` (image) whose nominal place is `nominal`. False when a point misses the plane.
bool setPoseOffset(StepResult& r, const std::optional<WorldMapping>& plane, cv::Point2d nominal,
                   cv::Point2d found, double angleDeg);

}  // namespace facet::service
