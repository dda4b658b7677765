#include "algorithms/scan/carmen_log.hpp"

#include <charconv>
#include <cmath>
#include <numbers>
#include <sstream>
#include <string_view>

namespace facet::scan {
namespace {

// Splits a line into whitespace-separated fields (views into the line).
std::vector<std::string_view> fields(std::string_view line) {
  std::vector<std::string_view> out;
  std::size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && (line[i] == ' ' || line[i] == '\t' || line[i] == '\r')) ++i;
    const std::size_t start = i;
    while (i < line.size() && line[i] != ' ' && line[i] != '\t' && line[i] != '\r') ++i;
    if (i > start) out.push_back(line.substr(start, i - start));
  }
  return out;
}

// Parses a number; "nan", "inf" are accepted (they are dropped later as bad ranges).
bool parseNumber(std::string_view text, double& value) {
  const char* end = text.data() + text.size();
  const auto [ptr, ec] = std::from_chars(text.data(), end, value);
  return ec == std::errc() && ptr == end;
}

}  // namespace

std::vector<CarmenLaserScan> readCarmenLog(std::istream& in, const std::string& source,
                                           const RangeLimits& limits) {
  std::vector<CarmenLaserScan> scans;
  std::string line;
  int lineNumber = 0;
  std::vector<double> ranges;
  while (std::getline(in, line)) {
    ++lineNumber;
    const auto f = fields(line);
    if (f.empty() || f[0] != "FLASER") continue;
    const auto fail = [&](const std::string& message) {
      throw ScanFormatError(source, lineNumber, "FLASER: " + message);
    };
    double count = 0.0;
    if (f.size() < 2 || !parseNumber(f[1], count) || count < 1.0 || count != std::floor(count) ||
        count > 100000.0)
      fail("expected a beam count after FLASER");
    const auto n = static_cast<std::size_t>(count);
    // n ranges, then x y theta odom_x odom_y odom_theta ipc_timestamp (host and logger time
    // follow but are not needed).
    if (f.size() < 2 + n + 7)
      fail("expected " + std::to_string(n) + " ranges and 7 pose/time fields, got " +
           std::to_string(f.size() - 2) + " fields");
    ranges.resize(n);
    for (std::size_t i = 0; i < n; ++i) {
      if (!parseNumber(f[2 + i], ranges[i]))
        fail("range " + std::to_string(i + 1) + " is not a number: '" + std::string(f[2 + i]) +
             "'");
    }
    double values[7];
    for (std::size_t k = 0; k < 7; ++k) {
      if (!parseNumber(f[2 + n + k], values[k]) || !std::isfinite(values[k]))
        fail("pose/time field " + std::to_string(k + 1) + " is not a finite number: '" +
             std::string(f[2 + n + k]) + "'");
    }
    constexpr double kDeg = std::numbers::pi / 180.0;
    const double step = 180.0 / static_cast<double>(n - n % 2) * kDeg;
    CarmenLaserScan s;
    s.scan = scanFromRanges(ranges, -90.0 * kDeg, n > 1 ? step : 0.0, limits);
    s.pose = {values[0], values[1], values[2]};
    s.odometry = {values[3], values[4], values[5]};
    s.timestamp = values[6];
    s.line = lineNumber;
    scans.push_back(std::move(s));
  }
  return scans;
}

}  // namespace facet::scan
