#pragma once
// The GenICam pixel formats facet takes from an Aravis camera, and their OpenCV layouts.

#include <arv.h>

#include <optional>
#include <string>

#include "camera/sensor_image.hpp"

namespace facet {

// nullopt for a format facet does not decode.
std::optional<SensorLayout> layoutOf(ArvPixelFormat format);
// The OpenCV type of one frame's buffer in this layout.
int cvTypeOf(SensorLayout layout);
// Whether camera.pixel_format names one of the formats above ("Mono8", "BayerRG8", ...).
bool supportedPixelFormatName(const std::string& name);

}  // namespace facet
