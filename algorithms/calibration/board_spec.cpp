#include "algorithms/calibration/board_spec.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <iterator>
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

// OpenCV's predefined ArUco dictionaries, in the order of cv::aruco::PREDEFINED_DICTIONARY_NAME
// (the index is the id), with how many markers each holds. Kept here, not asked of OpenCV, so
// that a spec is checked without loading the dictionaries.
struct Dictionary {
  const char* name;
  int markers;
};
constexpr Dictionary kDictionaries[] = {
    {"DICT_4X4_50", 50},        {"DICT_4X4_100", 100},         {"DICT_4X4_250", 250},
    {"DICT_4X4_1000", 1000},    {"DICT_5X5_50", 50},           {"DICT_5X5_100", 100},
    {"DICT_5X5_250", 250},      {"DICT_5X5_1000", 1000},       {"DICT_6X6_50", 50},
    {"DICT_6X6_100", 100},      {"DICT_6X6_250", 250},         {"DICT_6X6_1000", 1000},
    {"DICT_7X7_50", 50},        {"DICT_7X7_100", 100},         {"DICT_7X7_250", 250},
    {"DICT_7X7_1000", 1000},    {"DICT_ARUCO_ORIGINAL", 1024}, {"DICT_APRILTAG_16h5", 30},
    {"DICT_APRILTAG_25h9", 35}, {"DICT_APRILTAG_36h10", 2320}, {"DICT_APRILTAG_36h11", 587},
};

std::string upper(std::string s) {
  for (char& c : s) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  return s;
}

// The dictionary's id for its name, with or without the DICT_ prefix, in any case; -1 if none.
int dictionaryId(const std::string& name) {
  const std::string want =
      upper(name.rfind("DICT_", 0) == 0 || name.rfind("dict_", 0) == 0 ? name : "DICT_" + name);
  for (std::size_t i = 0; i < std::size(kDictionaries); ++i)
    if (upper(kDictionaries[i].name) == want) return static_cast<int>(i);
  return -1;
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

std::string dictionaryName(int dictionary) {
  if (dictionary < 0 || dictionary >= static_cast<int>(std::size(kDictionaries))) return "?";
  return kDictionaries[dictionary].name;
}

std::string BoardSpec::text() const {
  const std::string grid = std::to_string(cols) + "x" + std::to_string(rows);
  if (kind == Kind::Chessboard) return "chessboard:" + grid + ":" + number(pitchMm);
  if (kind == Kind::Charuco)
    return "charuco:" + std::to_string(cols + 1) + "x" + std::to_string(rows + 1) + ":" +
           number(pitchMm) + ":" + number(markerMm) + ":" + dictionaryName(dictionary);
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
    if (parts.size() != 5) {
      why =
          "expected charuco:COLSxROWS:SQUARE_MM:MARKER_MM:DICT (squares, e.g. "
          "charuco:12x9:15:11:DICT_5X5_100), got '" +
          spec + "'";
      return std::nullopt;
    }
    b.kind = BoardSpec::Kind::Charuco;
  } else {
    why = "unknown board kind '" + parts[0] + "' (chessboard, circles, charuco)";
    return std::nullopt;
  }
  if (b.kind == BoardSpec::Kind::Charuco) {
    // Counted in squares: the inner corners are one fewer each way.
    if (!parseGrid(parts[1], b.cols, b.rows) || b.cols < 3 || b.rows < 3) {
      why = "grid '" + parts[1] + "' must be COLSxROWS squares with 3..200 each";
      return std::nullopt;
    }
    b.cols -= 1, b.rows -= 1;
  } else if (!parseGrid(parts[1], b.cols, b.rows)) {
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
  } else if (b.kind == BoardSpec::Kind::Charuco) {
    const auto marker = positiveNumber(parts[3]);
    if (!marker || *marker >= b.pitchMm) {
      why = "marker side '" + parts[3] + "' must be positive and smaller than the square (" +
            parts[2] + " mm)";
      return std::nullopt;
    }
    b.markerMm = *marker;
    b.dictionary = dictionaryId(parts[4]);
    if (b.dictionary < 0) {
      why = "unknown ArUco dictionary '" + parts[4] + "' (";
      for (std::size_t i = 0; i < std::size(kDictionaries); ++i)
        why += (i ? ", " : "") + std::string(kDictionaries[i].name);
      why += ")";
      return std::nullopt;
    }
    // OpenCV's board puts a marker in every light square: half of them, rounded down.
    const int markers = (b.cols + 1) * (b.rows + 1) / 2;
    if (markers > kDictionaries[b.dictionary].markers) {
      why = "a board of " + parts[1] + " squares has " + std::to_string(markers) + " markers; " +
            kDictionaries[b.dictionary].name + " holds only " +
            std::to_string(kDictionaries[b.dictionary].markers);
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
