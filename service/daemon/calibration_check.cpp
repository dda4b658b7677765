#include "service/daemon/calibration_check.hpp"

#include <stdexcept>

#include "camera/image_codecs.hpp"
#include "camera/image_file_list.hpp"

namespace facet::service {
namespace {

std::string text(cv::Size s) {
  return std::to_string(s.width) + "x" + std::to_string(s.height);
}

}  // namespace

std::optional<cv::Size> expectedFrameSize(const CameraSettings& camera) {
  switch (camera.backend) {
    case CameraBackend::Replay: {
      try {
        const auto files = listRecordedFiles(
            camera.replay.folder, camera.replay.glob,
            {".png", ".tif", ".tiff", ".bmp", ".pgm", ".ppm", ".pnm", ".pbm", ".jpg", ".jpeg"});
        for (const auto& f : files) {
          const cv::Mat image = readImage(f, cv::IMREAD_UNCHANGED);
          if (!image.empty()) return image.size();
        }
      } catch (const std::exception&) {
        // The camera reports an unreadable folder itself, when it opens.
      }
      return std::nullopt;
    }
    case CameraBackend::Aravis:
      if (camera.aravis.region.width > 0 && camera.aravis.region.height > 0)
        return cv::Size(camera.aravis.region.width, camera.aravis.region.height);
      return std::nullopt;
    case CameraBackend::V4l2:
      if (camera.v4l2.width > 0 && camera.v4l2.height > 0)
        return cv::Size(camera.v4l2.width, camera.v4l2.height);
      return std::nullopt;
  }
  return std::nullopt;
}

void checkCalibrationImageSize(const config::StationConfig& station) {
  const auto& cal = station.calibration;
  if (cal.cameraMatrix.empty() || cal.imageSize.empty()) return;
  const auto frames = expectedFrameSize(station.camera);
  if (frames && *frames != cal.imageSize)
    throw std::runtime_error(
        "calibration file " + (cal.file ? cal.file->string() : std::string("?")) +
        " was made for " + text(cal.imageSize) + " images, but the camera delivers " +
        text(*frames) + ": calibrate again at this resolution (facet calibrate)");
}

}  // namespace facet::service
