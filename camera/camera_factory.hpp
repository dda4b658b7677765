#pragma once
// makeCamera: the one place that knows which backend class implements which settings.

#include <memory>

#include "camera/camera.hpp"
#include "camera/camera_settings.hpp"

namespace facet {

// Builds the camera `settings.backend` asks for; it is returned closed (call open()).
// Throws CameraError when the settings are unusable (e.g. replay without a folder), or when the
// backend's module cannot be loaded (aravis_backend.hpp).
std::unique_ptr<Camera> makeCamera(const CameraSettings& settings);

}  // namespace facet
