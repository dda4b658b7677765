#include "service/cli/world_circle.hpp"

#include "algorithms/calibration/plane_circle.hpp"
#include "config/calibration_file.hpp"
#include "service/cli/command_line.hpp"

namespace facet::cli {
namespace {

config::CalibrationData usableCalibration(const std::string& file, cv::Size imageSize) {
  config::Diagnostics problems;
  auto data = config::readCalibrationFile(file, problems);
  if (!data) throw InputError("calibration file not usable:\n" + problems.text());
  const auto sizeText = [](cv::Size s) {
    return std::to_string(s.width) + "x" + std::to_string(s.height);
  };
  if (data->camera && !data->camera->imageSize.empty() && data->camera->imageSize != imageSize)
    throw InputError(file + ": the calibration was made for " + sizeText(data->camera->imageSize) +
                     " images, this image is " + sizeText(imageSize));
  return std::move(*data);
}

}  // namespace

void checkCalibrationFor(const std::string& file, cv::Size imageSize) {
  (void)usableCalibration(file, imageSize);
}

nlohmann::json worldCircle(const std::string& file, cv::Size imageSize,
                           const CircleMeasurement& m) {
  const config::CalibrationData data = usableCalibration(file, imageSize);
  if (data.camera && data.plane) {
    const WorldMapping mapping(*data.camera, *data.plane);
    const auto c = circleInPlane(m, mapping);
    if (!c)
      throw MeasurementFailure("off_plane",
                               "the circle's rim does not map into the measuring plane");
    return {{"x_mm", c->centreMm.x},
            {"y_mm", c->centreMm.y},
            {"diameter_mm", c->diameterMm},
            {"rms_mm", c->rmsMm},
            {"calibration", data.kind()}};
  }
  if (data.mmPerPixel <= 0)
    throw InputError(file +
                     ": the calibration has a lens model but neither a plane nor mm_per_pixel");
  const double s = data.mmPerPixel;
  return {{"x_mm", m.centre.x * s},
          {"y_mm", m.centre.y * s},
          {"diameter_mm", m.diameter * s},
          {"calibration", "scale only, no lens model"}};
}

}  // namespace facet::cli
