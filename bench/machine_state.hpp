#pragma once
// What a benchmark prints about the machine beside its timings: the process's CPU time and the
// load average (a busy machine explains a slow row).

#include <time.h>

#include <fstream>
#include <string>

namespace facet::bench {

inline double cpuSeconds(clockid_t clock = CLOCK_PROCESS_CPUTIME_ID) {
  timespec t{};
  ::clock_gettime(clock, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

// The 1, 5 and 15 minute load averages, as /proc/loadavg gives them ("1.02 0.87 0.55").
inline std::string loadAverage() {
  std::ifstream f("/proc/loadavg");
  std::string a, b, c;
  f >> a >> b >> c;
  return a + " " + b + " " + c;
}

}  // namespace facet::bench
