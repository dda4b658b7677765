#pragma once
// ProcessSample: what /proc says about a running process at one moment: resident memory, open
// file descriptors and threads. The soak reads it for facetd every sampling period.

#include <sys/types.h>

#include <optional>

namespace facet::soak {

struct ProcessSample {
  double rssMiB = 0;  // VmRSS of /proc/PID/status, MiB
  int fds = 0;        // entries of /proc/PID/fd
  int threads = 0;    // Threads of /proc/PID/status
};

// nullopt when the process is gone (or /proc cannot be read).
std::optional<ProcessSample> sampleProcess(pid_t pid);

}  // namespace facet::soak
