#include "service/cli/measuring_plane.hpp"

#include <cmath>

#include "config/calibration_file.hpp"
#include "service/cli/command_line.hpp"

namespace facet::cli {

MeasuringPlane::MeasuringPlane(const std::string& file, cv::Size imageSize) : file_(file) {
  config::Diagnostics problems;
  const auto data = config::readCalibrationFile(file, problems);
  if (!data) throw InputError("calibration file not usable:\n" + problems.text());
  const auto sizeText = [](cv::Size s) {
    return std::to_string(s.width) + "x" + std::to_string(s.height);
  };
  if (data->camera && !data->camera->imageSize.empty() && data->camera->imageSize != imageSize)
    throw InputError(file + ": the calibration was made for " + sizeText(data->camera->imageSize) +
                     " images, this image is " + sizeText(imageSize));
  kind_ = data->kind();
  if (data->camera && data->plane) {
    mapping_.emplace(*data->camera, *data->plane);
    return;
  }
  if (data->mmPerPixel <= 0)
    throw InputError(file +
                     ": the calibration has a lens model but neither a plane nor mm_per_pixel");
  mmPerPixel_ = data->mmPerPixel;
}

cv::Point2d MeasuringPlane::toPlane(cv::Point2d pixel) const {
  if (!mapping_) return pixel * mmPerPixel_;
  const cv::Point2d q = mapping_->toPlane(pixel);
  if (!std::isfinite(q.x) || !std::isfinite(q.y))
    throw MeasurementFailure(
        "off_plane", "the point (" + std::to_string(pixel.x) + ", " + std::to_string(pixel.y) +
                         ") does not map into the measuring plane of " + file_);
  return q;
}

double MeasuringPlane::mmPerPixelAt(cv::Point2d pixel) const {
  return mapping_ ? mapping_->mmPerPixelAt(pixel) : mmPerPixel_;
}

double MeasuringPlane::span(const MeasuringPath& path, double s0, double s1) const {
  if (!mapping_) return (s1 - s0) * mmPerPixel_;
  const double mm = spanInPlane(path, mapping(), s0, s1);
  if (!std::isfinite(mm))
    throw MeasurementFailure("off_plane",
                             "the caliper's axis does not map into the measuring "
                             "plane of " +
                                 file_);
  return mm;
}

LineInPlane MeasuringPlane::line(const MeasuringRect& rect, const LineMeasurement& m) const {
  LineInPlane out = lineInPlane(rect, m, mapping());
  if (!mapping_) {
    out.p1 *= mmPerPixel_;
    out.p2 *= mmPerPixel_;
    out.offset *= mmPerPixel_;
    out.straightness *= mmPerPixel_;
    out.rms *= mmPerPixel_;
  }
  return out;
}

}  // namespace facet::cli
