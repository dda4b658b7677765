#pragma once
// The station's calibration file: what `facet calibrate` writes and facetd reads.
//
// facet's format is YAML (read with positions, so every problem is reported as
// file:line:column):
//
//   format: facet-calibration 1
//   board: chessboard:11x8:10          # the plate it was made with (informative)
//   image_size: [1280, 1024]           # the camera's frames; facetd refuses other sizes
//   rms_px: 0.012                      # RMS reprojection error of the calibration (informative)
//   camera_matrix: [[fx, 0, cx], [0, fy, cy], [0, 0, 1]]     # pixels
//   distortion: [k1, k2, p1, p2, k3]   # OpenCV's order; 4, 5, 8, 12 or 14 values
//   plane:                             # the measuring plane (optional)
//     rotation: [[..], [..], [..]]     # plate frame -> camera frame
//     translation_mm: [x, y, z]        # the plate's origin in the camera frame
//     offset_mm: 0                     # the measured face's height above the plate
//   mm_per_pixel: 0.2                  # the scale-only fallback (with a plane: its scale at the
//                                      # image centre)
//
// Every key but `format` is optional, with these rules: camera_matrix, distortion and
// image_size come together; a plane needs them; a file needs a lens model or mm_per_pixel (a
// lens model without plane or scale leaves the scale to the station's own mm_per_pixel).
// A file with mm_per_pixel alone is valid: "scale only, no lens model".
//
// Files written by OpenCV's FileStorage (first line "%YAML:1.0": camera_matrix,
// distortion_coefficients, mm_per_pixel, optionally image_width/image_height) are still read.

#include <filesystem>
#include <optional>
#include <string>

#include <opencv2/core.hpp>

#include "algorithms/calibration/camera_model.hpp"
#include "algorithms/calibration/world_mapping.hpp"
#include "config/diagnostic.hpp"

namespace facet::config {

struct CalibrationData {
  double mmPerPixel = 0.0;            // 0 = not given
  std::optional<CameraModel> camera;  // imageSize may be empty for an OpenCV file without one
  std::optional<PlanePose> plane;
  double rmsPx = 0.0;
  std::string board;

  // "lens model + plane", "lens model, scale only", "scale only, no lens model".
  [[nodiscard]] std::string kind() const;
};

// Reads a calibration file; problems go to `out` (file:line:column), nullopt on any error.
std::optional<CalibrationData> readCalibrationFile(const std::filesystem::path& file,
                                                   Diagnostics& out);

// The file's text in facet's format; `comment` (may be several lines) goes on top as # lines.
std::string calibrationFileText(const CalibrationData& data, const std::string& comment);

}  // namespace facet::config
