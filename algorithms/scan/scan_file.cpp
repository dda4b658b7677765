#include "algorithms/scan/scan_file.hpp"

#include <sstream>
#include <stdexcept>

#include <zlib.h>

namespace facet::scan {

std::string readTextFile(const std::string& path) {
  // gzread passes plain files through unchanged, so one path serves both.
  gzFile file = gzopen(path.c_str(), "rb");
  if (file == nullptr) throw std::runtime_error(path + ": cannot open file");
  std::string text;
  char buffer[1 << 16];
  while (true) {
    const int n = gzread(file, buffer, sizeof(buffer));
    if (n < 0) {
      int code = 0;
      const std::string message = gzerror(file, &code);
      gzclose(file);
      throw std::runtime_error(path + ": cannot read file: " + message);
    }
    if (n == 0) break;
    text.append(buffer, static_cast<std::size_t>(n));
  }
  gzclose(file);
  return text;
}

std::vector<CarmenLaserScan> readCarmenLogFile(const std::string& path, const RangeLimits& limits) {
  std::istringstream in(readTextFile(path));
  return readCarmenLog(in, path, limits);
}

Scan readScanCsvFile(const std::string& path, const RangeLimits& limits) {
  std::istringstream in(readTextFile(path));
  return readScanCsv(in, path, limits);
}

}  // namespace facet::scan
