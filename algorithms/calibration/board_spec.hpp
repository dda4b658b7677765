#pragma once
// BoardSpec: the calibration plate, parsed from `chessboard:COLSxROWS:SQUARE_MM`,
// `circles:COLSxROWS:PITCH_MM:DIAMETER_MM` or `charuco:COLSxROWS:SQUARE_MM:MARKER_MM:DICT`.
//
// Plate frame (design, "Conventions"): x along the columns, y along the rows, z = 0 on the
// plate's surface pointing into the plate, mm. Chessboard: COLS x ROWS inner corners, the origin
// at the inner corner next to the dark outer corner square (one even and one odd number of
// squares makes that corner unique). Circles: a symmetric grid of dark marks on a light plate,
// the origin at the centre of the first mark (the one nearest the image's top-left corner, since
// a symmetric grid looks the same turned by 180 degrees). ChArUco: COLS x ROWS squares, as
// OpenCV's CharucoBoard and the plate makers count them (a chessboard with ArUco markers of the
// dictionary DICT in its light squares); its pattern points are the (COLS-1) x (ROWS-1) inner
// corners, the origin at the corner next to the dark square at the board's first corner, which
// is OpenCV's charuco corner 0: the markers make every corner's identity known, so a view that
// shows only part of the plate is still usable.

#include <optional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

namespace facet {

struct BoardSpec {
  enum class Kind { Chessboard, Circles, Charuco };
  Kind kind = Kind::Chessboard;
  int cols = 0;             // inner corners (chessboard, charuco) or marks (circles) along x
  int rows = 0;             // along y
  double pitchMm = 0.0;     // square size (chessboard, charuco) or mark spacing (circles)
  double diameterMm = 0.0;  // circles: mark diameter
  double markerMm = 0.0;    // charuco: the side of a marker
  int dictionary = -1;      // charuco: OpenCV's predefined dictionary (cv::aruco::DICT_*)

  // Plate coordinates of the pattern points, row by row (x fastest), z = 0.
  [[nodiscard]] std::vector<cv::Point3d> platePoints() const;
  [[nodiscard]] int pointCount() const { return cols * rows; }
  [[nodiscard]] std::string text() const;  // back to the SPEC form
  // A board whose views may show part of the pattern (each point's identity is known).
  [[nodiscard]] bool partialViews() const { return kind == Kind::Charuco; }
};

// The name of a charuco dictionary as the SPEC gives it ("DICT_4X4_50").
std::string dictionaryName(int dictionary);

// Parses SPEC; on error returns nothing and sets `why`.
std::optional<BoardSpec> parseBoardSpec(const std::string& spec, std::string& why);

}  // namespace facet
