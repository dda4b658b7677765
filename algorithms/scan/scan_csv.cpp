#include "algorithms/scan/scan_csv.hpp"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <numbers>
#include <optional>
#include <string_view>
#include <vector>

namespace facet::scan {
namespace {

std::string_view trim(std::string_view s) {
  while (!s.empty() && std::isspace(static_cast<unsigned char>(s.front()))) s.remove_prefix(1);
  while (!s.empty() && std::isspace(static_cast<unsigned char>(s.back()))) s.remove_suffix(1);
  return s;
}

std::vector<std::string_view> cells(std::string_view line) {
  std::vector<std::string_view> out;
  std::size_t start = 0;
  while (true) {
    const std::size_t comma = line.find(',', start);
    out.push_back(trim(line.substr(start, comma - start)));
    if (comma == std::string_view::npos) break;
    start = comma + 1;
  }
  return out;
}

std::optional<double> number(std::string_view text) {
  double value = 0.0;
  if (!text.empty() && text.front() == '+') text.remove_prefix(1);
  const char* end = text.data() + text.size();
  const auto [ptr, ec] = std::from_chars(text.data(), end, value);
  if (text.empty() || ec != std::errc() || ptr != end) return std::nullopt;
  return value;
}

std::string lower(std::string_view s) {
  std::string out(s);
  std::transform(out.begin(), out.end(), out.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return out;
}

enum class Layout { Unknown, Cartesian, Polar };

}  // namespace

Scan readScanCsv(std::istream& in, const std::string& source, const RangeLimits& limits) {
  Scan scan;
  Layout layout = Layout::Unknown;
  int first = 0, second = 1;  // columns: x,y or angle,range
  std::size_t columns = 2;
  std::string line;
  int lineNumber = 0;
  while (std::getline(in, line)) {
    ++lineNumber;
    const std::string_view text = trim(line);
    if (text.empty() || text.front() == '#') continue;
    const auto row = cells(text);
    if (layout == Layout::Unknown && !number(row[0])) {
      // A header: name the columns.
      std::vector<std::string> names;
      for (const auto c : row) names.push_back(lower(c));
      const auto column = [&](std::initializer_list<const char*> wanted) {
        for (std::size_t i = 0; i < names.size(); ++i)
          for (const char* w : wanted)
            if (names[i] == w) return static_cast<int>(i);
        return -1;
      };
      const int x = column({"x"}), y = column({"y"});
      const int angle = column({"angle_deg", "angle"}), range = column({"range"});
      if (x >= 0 && y >= 0) {
        layout = Layout::Cartesian;
        first = x;
        second = y;
      } else if (angle >= 0 && range >= 0) {
        layout = Layout::Polar;
        first = angle;
        second = range;
      } else {
        throw ScanFormatError(
            source, lineNumber,
            "header must name columns x,y or angle_deg,range, got '" + std::string(text) + "'");
      }
      columns = names.size();
      continue;
    }
    if (layout == Layout::Unknown) {
      layout = Layout::Cartesian;  // no header: x,y
      columns = 2;
    }
    if (row.size() != columns)
      throw ScanFormatError(source, lineNumber,
                            "expected " + std::to_string(columns) +
                                " comma-separated values, got " + std::to_string(row.size()));
    const auto u = number(row[static_cast<std::size_t>(first)]);
    const auto v = number(row[static_cast<std::size_t>(second)]);
    if (!u || !v)
      throw ScanFormatError(source, lineNumber, "not a number in '" + std::string(text) + "'");
    if (layout == Layout::Cartesian) {
      if (std::isfinite(*u) && std::isfinite(*v)) scan.points.emplace_back(*u, *v);
    } else {
      const double a = *u * std::numbers::pi / 180.0;
      const auto polar = scanFromPolar(std::span(&a, 1), std::span(&*v, 1), limits);
      scan.points.insert(scan.points.end(), polar.points.begin(), polar.points.end());
    }
  }
  return scan;
}

}  // namespace facet::scan
