#pragma once
// WorldMapping: subpixel image points <-> millimetres in the measuring plane.
//
// The measuring plane is the calibration plate's plane (plate frame: x along the columns, y along
// the rows, z into the plate, mm) shifted towards the camera by `offsetMm` (parts whose measured
// face stands above the plate's surface): the plane z = -offsetMm. A pixel is undistorted into a
// ray of the camera and the ray intersected with that plane; nothing resamples the image.
// Plane coordinates are (x, y) of the plate frame, mm.

#include <vector>

#include <opencv2/core.hpp>

#include "algorithms/calibration/camera_model.hpp"

namespace facet {

struct PlanePose {
  cv::Matx33d rotation = cv::Matx33d::eye();  // plate frame -> camera frame
  cv::Vec3d translationMm{0, 0, 0};           // the plate origin in the camera frame, mm
  double offsetMm = 0.0;                      // the measuring plane's height above the plate
};

class WorldMapping {
 public:
  WorldMapping(CameraModel camera, PlanePose plane);

  // Image pixel -> plane mm. NaN when the ray misses the plane (parallel or behind the camera).
  [[nodiscard]] cv::Point2d toPlane(cv::Point2d pixel) const;
  [[nodiscard]] std::vector<cv::Point2d> toPlane(const std::vector<cv::Point2d>& pixels) const;
  // Plane mm -> image pixel.
  [[nodiscard]] cv::Point2d toImage(cv::Point2d planeMm) const;
  // Mean scale at an image point, mm per pixel (square root of the local area ratio).
  [[nodiscard]] double mmPerPixelAt(cv::Point2d pixel) const;

  [[nodiscard]] const CameraModel& camera() const { return camera_; }
  [[nodiscard]] const PlanePose& plane() const { return plane_; }

 private:
  CameraModel camera_;
  PlanePose plane_;
  cv::Vec3d origin_;  // the measuring plane's origin in the camera frame, mm
};

}  // namespace facet
