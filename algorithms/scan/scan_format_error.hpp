#pragma once
// The error every scan reader throws on malformed input: names the source and the line.

#include <stdexcept>
#include <string>

namespace facet::scan {

struct ScanFormatError : std::runtime_error {
  ScanFormatError(const std::string& source, int line, const std::string& message)
      : std::runtime_error(source + ":" + std::to_string(line) + ": " + message),
        source(source),
        line(line) {}
  std::string source;  // file name (or whatever the caller named the stream)
  int line = 0;        // 1-based
};

}  // namespace facet::scan
