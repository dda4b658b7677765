#pragma once
// Peak resident memory (VmHWM) of a process, read from /proc: the memory bound the hardening and
// daemon tests check for hostile image headers.

#include <sys/types.h>

#include <cstdint>
#include <fstream>
#include <string>

namespace facet::test {

// VmHWM from a /proc/<pid>/status file, bytes; 0 when the file or the line is missing (an
// ended process).
inline std::uint64_t peakResidentBytes(const std::string& statusFile) {
  std::ifstream status(statusFile);
  std::string key;
  while (status >> key) {
    if (key == "VmHWM:") {
      std::uint64_t kb = 0;
      status >> kb;
      return kb * 1024;
    }
    status.ignore(1 << 20, '\n');
  }
  return 0;
}

inline std::uint64_t peakResidentBytes(pid_t pid) {
  return peakResidentBytes("/proc/" + std::to_string(pid) + "/status");
}

inline std::uint64_t ownPeakResidentBytes() {
  return peakResidentBytes("/proc/self/status");
}

}  // namespace facet::test
