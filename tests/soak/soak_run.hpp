#pragma once
// SoakRun: the real facetd replaying a recorded folder in a loop for many parts (free run, no
// PLC, nothing dropped), sampled every period from the outside: resident memory, open file
// descriptors and threads from /proc, parts done and the publish-stage histogram from /metrics.
// After facetd exits, the results database gives every part's inspection time and verdict.
//
// The parts are split into equal windows (the table's rows). The first `warmupWindows` are the
// warm-up (models loaded, archive and SQLite caches filling, allocator arenas growing); the
// judgement compares the last window with the baseline: the `baselineWindows` windows after the
// warm-up, taking their highest RSS, fd and thread figures and the p99 over all their parts.
// Why more than one: glibc sometimes gives ~10 MiB back to the system for a whole window; a
// baseline taken from such a dip alone would report growth that is not there. A dip in the
// last window can only hide growth of that size, never invent it.

#include <chrono>
#include <cstdint>
#include <iosfwd>
#include <map>
#include <string>
#include <vector>

namespace facet::soak {

struct SoakOptions {
  std::string facetd;  // path of the facetd binary
  std::uint64_t parts = 2000;
  int windows = 10;
  int warmupWindows = 1;
  int baselineWindows = 2;
  std::chrono::milliseconds samplePeriod{500};
  // The lightest demo recipe (fiducial board, id 3) and its recorded images.
  int recipe = 3;
  std::string replayFolder;  // looped; its sidecars give each part's expected verdict
  std::string recipesFolder;
  std::string calibrationFile;
  // Where the station file, results database, archive and facetd's log go; empty: a temporary
  // folder removed at the end.
  std::string workDir;
  std::map<std::string, std::string> environment;  // added to facetd's
  double archiveQuotaMb = 50;  // failed parts' images are archived, the quota makes it evict
  // Judgement bounds.
  double maxRssGrowth = 0.05;  // last window's peak RSS vs the baseline's
  int maxFdGrowth = 0;         // last window's fewest fds vs the baseline's
  int maxThreadGrowth = 0;
  double maxP99Ratio = 1.5;  // inspection p99, last window vs the baseline; 0 = not judged
  std::chrono::seconds timeout{3600};
  bool progress = false;  // one line on stderr per window while running
};

struct SoakWindow {
  std::uint64_t firstPart = 0, lastPart = 0;  // part ids, inclusive
  double seconds = 0;                         // wall time the window took
  int samples = 0;                            // /proc samples taken during the window
  double rssMiB = 0;                          // the highest RSS sampled
  int fds = 0;                                // the fewest open fds sampled
  int maxFds = 0;                             // the most open fds sampled
  int threads = 0;                            // the fewest threads sampled
  double p50Ms = 0, p99Ms = 0;                // inspection time, exact (results database)
  double publishP99Ms = 0;  // publish stage (PLC, store, archive): histogram bucket bound
};

struct SoakReport {
  std::vector<SoakWindow> windows;
  int exitCode = -1;  // facetd's
  double seconds = 0;
  std::uint64_t partsStored = 0;
  std::uint64_t partsMissing = 0;  // ids 1..parts absent from the database
  std::uint64_t errorParts = 0;    // stored with verdict "error"
  std::uint64_t unexpected = 0;    // verdict differs from the sidecar's expected verdict
  std::string integrity;           // PRAGMA integrity_check
  double databaseMiB = 0;          // results database and its WAL on disk at the end
  double archiveMiB = 0;           // archived images on disk at the end (quota: archiveQuotaMb)
  std::uint64_t archiveFiles = 0;
  // The baseline (see above) and the judgement, last window vs baseline.
  double baselineRssMiB = 0;
  int baselineFds = 0;
  int baselineThreads = 0;
  double baselineP99Ms = 0;
  double rssGrowth = 0;
  int fdGrowth = 0;
  int threadGrowth = 0;
  double p99Ratio = 0;
  std::vector<std::string> failures;  // one sentence per bound not met; empty = pass
  [[nodiscard]] bool ok() const { return failures.empty(); }
};

// Runs the soak; throws std::runtime_error when facetd cannot be started or sampled at all.
SoakReport runSoak(const SoakOptions& options);

// The table (window, parts, seconds, RSS MiB, fds, threads, p50, p99, publish p99) and the
// verdict, as the closing note quotes them.
void printSoakReport(std::ostream& out, const SoakOptions& options, const SoakReport& report);

}  // namespace facet::soak
