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

double MeasuringPlane::midpoint(const MeasuringPath& path, double s0, double s1) const {
  const double s = midpointInPlane(path, mapping(), s0, s1);
  if (!std::isfinite(s))
    throw MeasurementFailure(
        "off_plane", "the caliper's axis does not map into the measuring plane of " + file_);
  return s;
}

LineInPlane MeasuringPlane::line(const MeasuringRect& rect, const LineMeasurement& m) const {
  auto out = lineInPlane(rect, m, mapping());
  if (!out)
    throw MeasurementFailure("off_plane",
                             "the line does not map into the measuring plane of " + file_);
  if (!mapping_) {
    out->p1 *= mmPerPixel_;
    out->p2 *= mmPerPixel_;
    out->offset *= mmPerPixel_;
    out->straightness *= mmPerPixel_;
    out->rms *= mmPerPixel_;
  }
  return *out;
}

PlaneBlob MeasuringPlane::blob(const Blob& b) const {
  if (!mapping_)
    return {b.centroid * mmPerPixel_, b.area * mmPerPixel_ * mmPerPixel_,
            b.majorRadius * mmPerPixel_, b.minorRadius * mmPerPixel_, b.angle};
  const auto q = blobInPlane(b, *mapping_);
  if (!q)
    throw MeasurementFailure("off_plane", "the blob at (" + std::to_string(b.centroid.x) + ", " +
                                              std::to_string(b.centroid.y) +
                                              ") does not map into the measuring plane of " +
                                              file_);
  return *q;
}

}  // namespace facet::cli
