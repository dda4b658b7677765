#pragma once
// BoardSpec: the calibration plate, parsed from `chessboard:COLSxROWS:SQUARE_MM` or
// `circles:COLSxROWS:PITCH_MM:DIAMETER_MM`.
//
// Plate frame (design, "Conventions"): x along the columns, y along the rows, z = 0 on the
// plate's surface pointing into the plate, mm. Chessboard: COLS x ROWS inner corners, the origin
// at the inner corner next to the dark outer corner square (one even and one odd number of
// squares makes that corner unique). Circles: a symmetric grid of dark marks on a light plate,
// the origin at the centre of the first mark (the one nearest the image's top-left corner, since
// a symmetric grid looks the same turned by 180 degrees).

#include <optional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

namespace facet {

struct BoardSpec {
  enum class Kind { Chessboard, Circles };
  Kind kind = Kind::Chessboard;
  int cols = 0;             // inner corners (chessboard) or marks (circles) along x
  int rows = 0;             // along y
  double pitchMm = 0.0;     // square size (chessboard) or distance between mark centres (circles)
  double diameterMm = 0.0;  // circles: mark diameter

  // Plate coordinates of the pattern points, row by row (x fastest), z = 0.
  [[nodiscard]] std::vector<cv::Point3d> platePoints() const;
  [[nodiscard]] int pointCount() const { return cols * rows; }
  [[nodiscard]] std::string text() const;  // back to the SPEC form
};

// Parses SPEC; on error returns nothing and sets `why`.
std::optional<BoardSpec> parseBoardSpec(const std::string& spec, std::string& why);

}  // namespace facet
