#pragma once
// CameraModel: OpenCV's pinhole camera with lens distortion, and the exact inverse of its
// distortion for single points.
//
// Pixel coordinates follow the design (centre of pixel (0,0) at (0,0)), which is also OpenCV's
// convention for calibrateCamera and projectPoints. "Normalised" coordinates are (X/Z, Y/Z) of a
// point in the camera frame (x right, y down, z along the optical axis).

#include <vector>

#include <opencv2/core.hpp>

namespace facet {

struct CameraModel {
  cv::Matx33d cameraMatrix = cv::Matx33d::eye();  // [[fx, 0, cx], [0, fy, cy], [0, 0, 1]], px
  cv::Mat distortion;  // 1xN CV_64F: k1 k2 p1 p2 [k3 [k4 k5 k6 [s1..s4 [tx ty]]]]; empty = none
  cv::Size imageSize;  // the size of the images the model was made for

  // Pixel -> normalised, undistorted. Iterates until the point reprojects to within 1e-9 px
  // (OpenCV's undistortPoints stops after a fixed number of fixed-point steps, which leaves
  // tenths of a pixel in the corners of a strongly distorted lens).
  [[nodiscard]] cv::Point2d undistort(cv::Point2d pixel) const;
  [[nodiscard]] std::vector<cv::Point2d> undistort(const std::vector<cv::Point2d>& pixels) const;
  // Normalised, undistorted -> pixel.
  [[nodiscard]] cv::Point2d distort(cv::Point2d normalised) const;
  // A camera-frame point -> pixel.
  [[nodiscard]] cv::Point2d project(const cv::Vec3d& cameraPoint) const;
};

}  // namespace facet
