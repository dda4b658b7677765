#pragma once
// Circular marks of a circle-grid plate, centred from their subpixel rims.
//
// OpenCV's findCirclesGrid finds and orders the grid; each mark's rim is then taken from
// facet's Facet-model subpixel edges and fitted with a conic. A circle seen at an angle is an
// ellipse whose centre is NOT the image of the circle's centre (up to tenths of a pixel on a
// tilted plate); the true centre is the pole of the plate's vanishing line with respect to the
// rim's conic, fitted in undistorted coordinates. That needs the camera and the plate's
// orientation, so calibration starts from the ellipse centres and repeats with its own estimate
// (camera_calibration.cpp).

#include <vector>

#include <opencv2/core.hpp>

#include "algorithms/calibration/board_spec.hpp"
#include "algorithms/calibration/camera_model.hpp"
#include "algorithms/calibration/pattern_detection.hpp"

namespace facet {

struct CircleMarks {
  PatternDetection detection;                  // points: the rims' ellipse centres
  std::vector<std::vector<cv::Point2d>> rims;  // subpixel rim points of each mark, pixels
};

// `image`: 8-bit or 16-bit grey, dark marks on a light plate.
CircleMarks detectCircleMarks(const cv::Mat& image, const BoardSpec& board);

// The images of the marks' centres for a camera and the plate's rotation (plate -> camera).
std::vector<cv::Point2d> perspectiveCentres(const CircleMarks& marks, const CameraModel& camera,
                                            const cv::Matx33d& plateRotation);

}  // namespace facet
