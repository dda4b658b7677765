#include "algorithms/calibration/board_spec.hpp"

#include <cmath>
#include <sstream>

namespace facet {
namespace {

std::vector<std::string> split(const std::string& s, char sep) {
  std::vector<std::string> parts;
  std::string part;
  std::istringstream in(s);
  while (std::getline(in, part, sep)) parts.push_back(part);
  if (!s.empty() && s.back() == sep) parts.emplace_back();
  return parts;
}

std::optional<double> positiveNumber(const std::string& s) {
  try {
    std::size_t used = 0;
    const double v = std::stod(s, &used);
    if (used != s.size() || !std::isfinite(v) || v <= 0) return std::nullopt;
    return v;
  } catch (const std::exception&) {
    return std::nullopt;
  }
}

bool parseGrid(const std::string& s, int& cols, int& rows) {
  const auto x = s.find('x');
  if (x == std::string::npos) return false;
  try {
    std::size_t a = 0, b = 0;
    cols = std::stoi(s.substr(0, x), &a);
    rows = std::stoi(s.substr(x + 1), &b);
    return a == x && b == s.size() - x - 1 && cols >= 2 && rows >= 2 && cols <= 200 && rows <= 200;
  } catch (const std::exception&) {
    return false;
  }
}

std::string number(double v) {
  std::ostringstream o;
  o << v;
  return o.str();
}

}  // namespace

std::vector<cv::Point3d> BoardSpec::platePoints() const {
  std::vector<cv::Point3d> points;
  points.reserve(static_cast<std::size_t>(pointCount()));
  for (int r = 0; r < rows; ++r)
    for (int c = 0; c < cols; ++c) points.emplace_back(c * pitchMm, r * pitchMm, 0.0);
  return points;
}

std::string BoardSpec::text() const {
  const std::string grid = std::to_string(cols) + "x" + std::to_string(rows);
  if (kind == Kind::Chessboard) return "chessboard:" + grid + ":" + number(pitchMm);
  return "circles:" + grid + ":" + number(pitchMm) + ":" + number(diameterMm);
}

std::optional<BoardSpec> parseBoardSpec(const std::string& spec, std::string& why) {
  const auto parts = split(spec, ':');
  BoardSpec b;
  if (parts.empty()) {
    why = "empty board spec";
    return std::nullopt;
  }
  if (parts[0] == "chessboard") {
    if (parts.size() != 3) {
      why = "expected chessboard:COLSxROWS:SQUARE_MM (inner corners), got '" + spec + "'";
      return std::nullopt;
    }
    b.kind = BoardSpec::Kind::Chessboard;
  } else if (parts[0] == "circles") {
    if (parts.size() != 4) {
      why = "expected circles:COLSxROWS:PITCH_MM:DIAMETER_MM, got '" + spec + "'";
      return std::nullopt;
    }
    b.kind = BoardSpec::Kind::Circles;
  } else if (parts[0] == "charuco") {
    why = "charuco boards are not supported yet: use chessboard:... or circles:...";
    return std::nullopt;
  } else {
    why = "unknown board kind '" + parts[0] + "' (chessboard, circles)";
    return std::nullopt;
  }
  if (!parseGrid(parts[1], b.cols, b.rows)) {
    why = "grid '" + parts[1] + "' must be COLSxROWS with 2..200 each";
    return std::nullopt;
  }
  const auto pitch = positiveNumber(parts[2]);
  if (!pitch) {
    why = "'" + parts[2] + "' is not a positive length in mm";
    return std::nullopt;
  }
  b.pitchMm = *pitch;
  if (b.kind == BoardSpec::Kind::Chessboard) {
    if ((b.cols + 1) % 2 == (b.rows + 1) % 2) {
      why = "a chessboard of " + parts[1] + " inner corners has " + std::to_string(b.cols + 1) +
            "x" + std::to_string(b.rows + 1) +
            " squares; one count must be even and one odd so that its origin is unique";
      return std::nullopt;
    }
  } else {
    const auto d = positiveNumber(parts[3]);
    if (!d || *d >= b.pitchMm) {
      why = "mark diameter '" + parts[3] + "' must be positive and smaller than the pitch";
      return std::nullopt;
    }
    b.diameterMm = *d;
  }
  return b;
}

}  // namespace facet
