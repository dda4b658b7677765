#include "tests/soak/process_sample.hpp"

#include <filesystem>
#include <fstream>
#include <string>

namespace facet::soak {

std::optional<ProcessSample> sampleProcess(pid_t pid) {
  const std::filesystem::path proc = "/proc/" + std::to_string(pid);
  std::ifstream status(proc / "status");
  if (!status) return std::nullopt;
  ProcessSample s;
  bool rss = false, threads = false;
  for (std::string line; std::getline(status, line);) {
    // "VmRSS:     123456 kB", "Threads:        7"
    if (line.starts_with("VmRSS:")) {
      s.rssMiB = std::stod(line.substr(6)) / 1024.0;
      rss = true;
    } else if (line.starts_with("Threads:")) {
      s.threads = std::stoi(line.substr(8));
      threads = true;
    }
  }
  // A zombie has no VmRSS line: the process has ended.
  if (!rss || !threads) return std::nullopt;
  std::error_code ec;
  for (std::filesystem::directory_iterator it(proc / "fd", ec), end; !ec && it != end;
       it.increment(ec))
    ++s.fds;
  if (ec) return std::nullopt;
  return s;
}

}  // namespace facet::soak
