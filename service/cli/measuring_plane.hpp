#pragma once
// `--calibration FILE` of the measuring commands (circle, caliper, line, blob): the station's
// calibration file, read and checked against the image, and the commands' pixels carried into
// the measuring plane. With a lens model and a plane, points go through the lens into the plane
// (as facetd measures); with a scale alone (mm_per_pixel), pixel values are multiplied by it.

#include <optional>
#include <string>

#include <opencv2/core.hpp>

#include "algorithms/calibration/plane_blob.hpp"
#include "algorithms/calibration/plane_measures.hpp"
#include "algorithms/calibration/world_mapping.hpp"

namespace facet::cli {

class MeasuringPlane {
 public:
  // Throws InputError for a file that cannot be used (its problems as file:line:column), one
  // made for images of another size, or one with a lens model but neither plane nor scale.
  // Called before measuring: a broken file is bad input even where nothing would be found.
  MeasuringPlane(const std::string& file, cv::Size imageSize);

  // "lens model + plane", "lens model, scale only" or "scale only, no lens model".
  [[nodiscard]] const std::string& kind() const { return kind_; }
  // The lens-and-plane mapping; null when the file gives a scale only.
  [[nodiscard]] const WorldMapping* mapping() const { return mapping_ ? &*mapping_ : nullptr; }

  // Image pixel -> plane mm. Throws MeasurementFailure "off_plane" when the pixel's ray misses
  // the plane.
  [[nodiscard]] cv::Point2d toPlane(cv::Point2d pixel) const;
  // mm per pixel about an image point (the plane's local scale).
  [[nodiscard]] double mmPerPixelAt(cv::Point2d pixel) const;
  // The signed length from axis position s0 to s1 of a caliper's path, mm (MeasurementFailure
  // "off_plane" where the path leaves the plane).
  [[nodiscard]] double span(const MeasuringPath& path, double s0, double s1) const;
  // The axis position halfway from s0 to s1 as the plane sees it (a pair's middle;
  // MeasurementFailure "off_plane" where the path leaves the plane).
  [[nodiscard]] double midpoint(const MeasuringPath& path, double s0, double s1) const;
  // A fitted line in the plane (ends, offset and deviations in mm; MeasurementFailure "off_plane"
  // where it leaves the plane).
  [[nodiscard]] LineInPlane line(const MeasuringRect& rect, const LineMeasurement& m) const;
  // A blob's centre, area and ellipse in the plane (the blob analysed with
  // BlobParams::keepCoverage when the file has a lens model and a plane; MeasurementFailure
  // "off_plane" where it leaves the plane).
  [[nodiscard]] PlaneBlob blob(const Blob& b) const;

 private:
  std::string file_, kind_;
  std::optional<WorldMapping> mapping_;
  double mmPerPixel_ = 0.0;  // the scale-only calibration's
};

}  // namespace facet::cli
