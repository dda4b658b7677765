#pragma once
// facetd refuses to start with a calibration made for another image size than its camera's
// frames: a lens model's centre and distortion are tied to the sensor's pixels, and applying
// them to other frames would measure wrong without any visible sign.

#include <optional>

#include <opencv2/core.hpp>

#include "camera/camera_settings.hpp"
#include "config/station_config.hpp"

namespace facet::service {

// The frame size the camera will deliver, as far as known before it is opened: the first image
// of a replay folder (its header), the region or width/height set for Aravis or V4L2.
std::optional<cv::Size> expectedFrameSize(const CameraSettings& camera);

// Throws std::runtime_error naming both sizes when the station's calibration file has a lens
// model made for another size than expectedFrameSize().
void checkCalibrationImageSize(const config::StationConfig& station);

}  // namespace facet::service
