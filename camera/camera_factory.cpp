#include "camera/camera_factory.hpp"

#include "camera/aravis_backend.hpp"
#include "camera/replay_camera.hpp"
#include "camera/v4l2_camera.hpp"

namespace facet {

std::unique_ptr<Camera> makeCamera(const CameraSettings& settings) {
  switch (settings.backend) {
    case CameraBackend::Replay:
      return std::make_unique<ReplayCamera>(settings.replay);
    case CameraBackend::Aravis:
      return makeAravisCamera(settings.aravis);  // loads the module on first use
    case CameraBackend::V4l2:
      return std::make_unique<V4l2Camera>(settings.v4l2);
  }
  throw CameraError("unknown camera backend");
}

}  // namespace facet
