#include "tests/soak/soak_run.hpp"

#include <signal.h>
#include <sqlite3.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <optional>
#include <sstream>
#include <stdexcept>

#include <httplib.h>

#include "tests/daemon/child_process.hpp"
#include "tests/soak/process_sample.hpp"

namespace facet::soak {
namespace {

using Clock = std::chrono::steady_clock;
namespace fs = std::filesystem;

// One look at facetd: /proc first, then /metrics (so the scrape's own connection is not among
// the fds counted).
struct Sample {
  ProcessSample process;
  std::uint64_t parts = 0;  // facet_parts_total over every verdict
  // facet_stage_ms{stage="publish"}: cumulative count per bucket upper bound (ms; +Inf last).
  std::vector<std::pair<double, std::uint64_t>> publishBuckets;
};

// One stored part, as the soak needs it.
struct StoredPart {
  std::int64_t id = 0;
  std::int64_t timeUs = 0;
  double inspectionMs = 0;
  std::string verdict, expected;
};

std::string stationFile(const SoakOptions& o, const std::string& dir) {
  std::ofstream f(dir + "/station.yaml");
  f << "schema_version: 1\nname: soak-station\ncamera:\n  backend: replay\n  replay:\n"
    << "    folder: " << o.replayFolder << "\n    glob: \"*.png\"\n    loop: true\n    fps: 0\n"
    << "    trigger: free_run\n    colour: mono\n";
  f << "recipes: " << o.recipesFolder << "\n";
  f << "results:\n  database: " << dir << "/results.db\n";
  f << "archive:\n  folder: " << dir << "/archive\n  quota_mb: " << o.archiveQuotaMb
    << "\n  keep: fail\n";
  f << "http:\n  bind: 127.0.0.1\n  port: 0\n";
  f << "calibration:\n  file: " << o.calibrationFile << "\n";
  return dir + "/station.yaml";
}

// `name{labels} value` -> labels and value; nullopt for comments and other metrics.
std::optional<std::pair<std::string, double>> series(const std::string& line,
                                                     const std::string& name) {
  if (!line.starts_with(name) || line.size() <= name.size()) return std::nullopt;
  std::string labels;
  std::size_t valueAt = name.size();
  if (line[valueAt] == '{') {
    const auto close = line.find('}', valueAt);
    if (close == std::string::npos) return std::nullopt;
    labels = line.substr(valueAt + 1, close - valueAt - 1);
    valueAt = close + 1;
  }
  if (valueAt >= line.size() || line[valueAt] != ' ') return std::nullopt;
  return std::pair{labels, std::stod(line.substr(valueAt + 1))};
}

void readMetrics(const std::string& text, Sample& s) {
  std::istringstream lines(text);
  s.parts = 0;
  s.publishBuckets.clear();
  for (std::string line; std::getline(lines, line);) {
    if (auto parts = series(line, "facet_parts_total")) {
      s.parts += static_cast<std::uint64_t>(parts->second);
    } else if (auto bucket = series(line, "facet_stage_ms_bucket")) {
      const auto& labels = bucket->first;
      if (labels.find("stage=\"publish\"") == std::string::npos) continue;
      const auto le = labels.find("le=\"");
      if (le == std::string::npos) continue;
      const std::string bound = labels.substr(le + 4, labels.find('"', le + 4) - le - 4);
      s.publishBuckets.emplace_back(bound == "+Inf" ? INFINITY : std::stod(bound),
                                    static_cast<std::uint64_t>(bucket->second));
    }
  }
}

std::optional<int> readPort(const std::string& file) {
  std::ifstream in(file);
  int port = 0;
  if (in >> port && port > 0) return port;
  return std::nullopt;
}

std::vector<StoredPart> storedParts(const std::string& database) {
  sqlite3* db = nullptr;
  if (sqlite3_open_v2(database.c_str(), &db, SQLITE_OPEN_READONLY, nullptr) != SQLITE_OK) {
    sqlite3_close(db);
    throw std::runtime_error(database + ": cannot open");
  }
  sqlite3_stmt* s = nullptr;
  const char* sql =
      "SELECT part_id, time_us, inspection_ms, verdict, expected FROM parts ORDER BY part_id";
  if (sqlite3_prepare_v2(db, sql, -1, &s, nullptr) != SQLITE_OK) {
    const std::string message = sqlite3_errmsg(db);
    sqlite3_close(db);
    throw std::runtime_error(database + ": " + message);
  }
  auto text = [&](int column) {
    const auto* p = sqlite3_column_text(s, column);
    return std::string(p ? reinterpret_cast<const char*>(p) : "");
  };
  std::vector<StoredPart> parts;
  while (sqlite3_step(s) == SQLITE_ROW)
    parts.push_back({sqlite3_column_int64(s, 0), sqlite3_column_int64(s, 1),
                     sqlite3_column_double(s, 2), text(3), text(4)});
  sqlite3_finalize(s);
  sqlite3_close(db);
  return parts;
}

std::string integrityCheck(const std::string& database) {
  sqlite3* db = nullptr;
  std::string answer = "cannot open";
  if (sqlite3_open_v2(database.c_str(), &db, SQLITE_OPEN_READONLY, nullptr) == SQLITE_OK) {
    sqlite3_stmt* s = nullptr;
    if (sqlite3_prepare_v2(db, "PRAGMA integrity_check", -1, &s, nullptr) == SQLITE_OK) {
      answer.clear();
      while (sqlite3_step(s) == SQLITE_ROW)
        answer += reinterpret_cast<const char*>(sqlite3_column_text(s, 0));
    }
    sqlite3_finalize(s);
  }
  sqlite3_close(db);
  return answer;
}

// Nearest-rank quantile of unsorted values (0 when empty).
double quantile(std::vector<double> values, double q) {
  if (values.empty()) return 0;
  std::sort(values.begin(), values.end());
  const auto rank = static_cast<std::size_t>(std::ceil(q * static_cast<double>(values.size())));
  return values[std::clamp<std::size_t>(rank, 1, values.size()) - 1];
}

// The bucket bound under which `q` of the observations between two scrapes fall.
double bucketQuantile(const std::vector<std::pair<double, std::uint64_t>>& before,
                      const std::vector<std::pair<double, std::uint64_t>>& after, double q) {
  if (after.empty()) return 0;
  auto countBefore = [&](std::size_t i) {
    return i < before.size() && before[i].first == after[i].first ? before[i].second : 0;
  };
  const double total = static_cast<double>(after.back().second - countBefore(after.size() - 1));
  if (total <= 0) return 0;
  for (std::size_t i = 0; i < after.size(); ++i)
    if (static_cast<double>(after[i].second - countBefore(i)) >= q * total) return after[i].first;
  return after.back().first;
}

std::size_t windowOf(std::uint64_t part, const SoakOptions& o) {
  // Window k holds parts (k*N/W, (k+1)*N/W].
  for (int k = 0; k < o.windows; ++k)
    if (part <= o.parts * static_cast<std::uint64_t>(k + 1) / static_cast<std::uint64_t>(o.windows))
      return static_cast<std::size_t>(k);
  return static_cast<std::size_t>(o.windows - 1);
}

void judge(const SoakOptions& o, SoakReport& r) {
  char buf[256];
  auto fail = [&](const char* format, auto... args) {
    std::snprintf(buf, sizeof buf, format, args...);
    r.failures.emplace_back(buf);
  };
  if (r.exitCode != 0) fail("facetd exited with %d", r.exitCode);
  if (r.partsStored != o.parts)
    fail("%llu of %llu parts stored", static_cast<unsigned long long>(r.partsStored),
         static_cast<unsigned long long>(o.parts));
  if (r.partsMissing > 0)
    fail("%llu part ids missing from the database",
         static_cast<unsigned long long>(r.partsMissing));
  if (r.errorParts > 0)
    fail("%llu parts not inspected (verdict error)", static_cast<unsigned long long>(r.errorParts));
  if (r.unexpected > 0)
    fail("%llu parts with a verdict other than their recorded one",
         static_cast<unsigned long long>(r.unexpected));
  if (r.integrity != "ok") fail("integrity_check: %s", r.integrity.c_str());
  if (r.archiveMiB > o.archiveQuotaMb)
    fail("archive holds %.1f MiB, quota %.1f MiB", r.archiveMiB, o.archiveQuotaMb);
  const auto base = static_cast<std::size_t>(o.warmupWindows);
  const auto baseEnd = base + static_cast<std::size_t>(o.baselineWindows);
  if (r.windows.size() < baseEnd + 1) {
    fail("only %zu windows reached: nothing to compare with the baseline", r.windows.size());
    return;
  }
  for (std::size_t k = base; k < r.windows.size(); ++k)
    if (r.windows[k].samples == 0) {
      fail("window %zu has no /proc sample (sample more often)", k + 1);
      return;
    }
  for (std::size_t k = base; k < baseEnd; ++k) {
    r.baselineRssMiB = std::max(r.baselineRssMiB, r.windows[k].rssMiB);
    r.baselineFds = std::max(r.baselineFds, r.windows[k].fds);
    r.baselineThreads = std::max(r.baselineThreads, r.windows[k].threads);
  }
  const SoakWindow& last = r.windows.back();
  r.rssGrowth = last.rssMiB / r.baselineRssMiB - 1.0;
  r.fdGrowth = last.fds - r.baselineFds;
  r.threadGrowth = last.threads - r.baselineThreads;
  r.p99Ratio = r.baselineP99Ms > 0 ? last.p99Ms / r.baselineP99Ms : 0;
  if (r.rssGrowth > o.maxRssGrowth)
    fail("RSS grew %.1f %% (%.1f -> %.1f MiB), bound %.1f %%", 100 * r.rssGrowth, r.baselineRssMiB,
         last.rssMiB, 100 * o.maxRssGrowth);
  if (r.fdGrowth > o.maxFdGrowth)
    fail("open fds grew by %d (%d -> %d)", r.fdGrowth, r.baselineFds, last.fds);
  if (r.threadGrowth > o.maxThreadGrowth)
    fail("threads grew by %d (%d -> %d)", r.threadGrowth, r.baselineThreads, last.threads);
  if (o.maxP99Ratio > 0 && r.p99Ratio > o.maxP99Ratio)
    fail("inspection p99 %.2fx the baseline's (%.2f -> %.2f ms), bound %.2fx", r.p99Ratio,
         r.baselineP99Ms, last.p99Ms, o.maxP99Ratio);
}

}  // namespace

SoakReport runSoak(const SoakOptions& o) {
  if (o.parts == 0 || o.warmupWindows < 0 || o.baselineWindows < 1 ||
      o.warmupWindows + o.baselineWindows >= o.windows)
    throw std::runtime_error(
        "soak: need parts > 0 and a window after the warm-up and baseline windows");
  std::optional<daemon_test::TempDir> temp;
  std::string dir = o.workDir;
  if (dir.empty()) {
    temp.emplace();
    dir = temp->path();
  }
  fs::create_directories(dir);
  const std::string database = dir + "/results.db";
  const std::string portFile = dir + "/http.port";
  for (const auto* stale : {"results.db", "results.db-wal", "results.db-shm", "http.port"})
    fs::remove(dir + "/" + stale);  // part ids must start at 1
  fs::remove_all(dir + "/archive");

  const auto started = Clock::now();
  daemon_test::ChildProcess facetd(
      {o.facetd, "--config", stationFile(o, dir), "--recipe", std::to_string(o.recipe), "--no-plc",
       "--max-parts", std::to_string(o.parts), "--block-when-behind", "--http-port-file", portFile,
       "--log-level", "warn"},
      o.environment, dir + "/facetd.log");

  // Per window: its samples; the last scrape of each window bounds its histogram delta.
  std::vector<std::vector<Sample>> samples(static_cast<std::size_t>(o.windows));
  std::optional<int> exitCode;
  std::optional<int> port;
  bool timedOut = false;
  std::size_t reported = 0;
  while (!(exitCode = facetd.wait(o.samplePeriod))) {
    if (Clock::now() - started > o.timeout) {
      // Finish the parts in progress and report what was reached.
      timedOut = true;
      facetd.signal(SIGTERM);
      exitCode = facetd.wait(std::chrono::seconds(60));
      break;
    }
    Sample s;
    const auto process = sampleProcess(facetd.pid());
    if (!process) continue;
    s.process = *process;
    if (!port) port = readPort(portFile);
    if (!port) continue;
    httplib::Client http("127.0.0.1", *port);
    http.set_connection_timeout(std::chrono::seconds(2));
    http.set_read_timeout(std::chrono::seconds(5));
    const auto res = http.Get("/metrics");
    if (!res || res->status != 200) continue;
    readMetrics(res->body, s);
    // Before the first part facetd is starting; after the last it is shutting down (threads
    // joined, files closed): neither belongs to a window.
    if (s.parts == 0 || s.parts >= o.parts) continue;
    const std::size_t k = windowOf(s.parts, o);
    samples[k].push_back(s);
    if (o.progress && k > reported) {
      for (; reported < k; ++reported) {
        const auto& w = samples[reported];
        if (w.empty()) continue;
        std::fprintf(stderr, "soak: window %zu done at %.0f s: RSS %.1f MiB, fds %d, threads %d\n",
                     reported + 1, std::chrono::duration<double>(Clock::now() - started).count(),
                     w.back().process.rssMiB, w.back().process.fds, w.back().process.threads);
      }
    }
  }
  if (!exitCode) exitCode = facetd.wait(std::chrono::seconds(10));

  SoakReport r;
  r.exitCode = exitCode.value_or(-1);
  r.seconds = std::chrono::duration<double>(Clock::now() - started).count();
  const auto parts = fs::exists(database) ? storedParts(database) : std::vector<StoredPart>{};
  r.partsStored = parts.size();
  std::map<std::int64_t, const StoredPart*> byId;
  for (const auto& p : parts) {
    byId[p.id] = &p;
    if (p.verdict == "error") ++r.errorParts;
    if (!p.expected.empty() && p.expected != p.verdict) ++r.unexpected;
  }
  const std::uint64_t reached = parts.empty() ? 0 : static_cast<std::uint64_t>(parts.back().id);
  for (std::uint64_t id = 1; id <= std::min(reached, o.parts); ++id)
    if (!byId.contains(static_cast<std::int64_t>(id))) ++r.partsMissing;
  r.integrity = fs::exists(database) ? integrityCheck(database) : "no database";
  auto mib = [](const fs::path& file) {
    std::error_code ec;
    const auto bytes = fs::file_size(file, ec);  // a WAL is gone after a clean close
    return ec ? 0.0 : static_cast<double>(bytes) / (1 << 20);
  };
  r.databaseMiB = mib(database) + mib(database + "-wal");
  std::error_code ec;
  for (fs::recursive_directory_iterator it(dir + "/archive", ec), end; !ec && it != end;
       it.increment(ec))
    if (it->is_regular_file(ec)) {
      r.archiveMiB += mib(it->path());
      ++r.archiveFiles;
    }

  std::vector<std::pair<double, std::uint64_t>> previousBuckets;
  for (int k = 0; k < o.windows; ++k) {
    SoakWindow w;
    w.firstPart =
        o.parts * static_cast<std::uint64_t>(k) / static_cast<std::uint64_t>(o.windows) + 1;
    w.lastPart = std::min<std::uint64_t>(reached, o.parts * static_cast<std::uint64_t>(k + 1) /
                                                      static_cast<std::uint64_t>(o.windows));
    if (w.firstPart > w.lastPart) break;  // not reached (timeout)
    std::vector<double> ms;
    for (auto id = w.firstPart; id <= w.lastPart; ++id)
      if (auto it = byId.find(static_cast<std::int64_t>(id)); it != byId.end())
        ms.push_back(it->second->inspectionMs);
    w.p50Ms = quantile(ms, 0.50);
    w.p99Ms = quantile(ms, 0.99);
    // Wall time from the part before the window to its last part (stored timestamps).
    const auto startId = static_cast<std::int64_t>(w.firstPart > 1 ? w.firstPart - 1 : 1);
    if (byId.contains(startId) && byId.contains(static_cast<std::int64_t>(w.lastPart)))
      w.seconds = static_cast<double>(byId[static_cast<std::int64_t>(w.lastPart)]->timeUs -
                                      byId[startId]->timeUs) /
                  1e6;
    const auto& ws = samples[static_cast<std::size_t>(k)];
    w.samples = static_cast<int>(ws.size());
    if (!ws.empty()) {
      w.fds = w.threads = INT32_MAX;
      for (const auto& s : ws) {
        w.rssMiB = std::max(w.rssMiB, s.process.rssMiB);
        w.fds = std::min(w.fds, s.process.fds);
        w.maxFds = std::max(w.maxFds, s.process.fds);
        w.threads = std::min(w.threads, s.process.threads);
      }
      w.publishP99Ms = bucketQuantile(previousBuckets, ws.back().publishBuckets, 0.99);
      previousBuckets = ws.back().publishBuckets;
    }
    r.windows.push_back(w);
  }
  {
    std::vector<double> ms;
    const auto from = o.parts * static_cast<std::uint64_t>(o.warmupWindows) /
                          static_cast<std::uint64_t>(o.windows) +
                      1;
    const auto to = o.parts * static_cast<std::uint64_t>(o.warmupWindows + o.baselineWindows) /
                    static_cast<std::uint64_t>(o.windows);
    for (auto id = from; id <= std::min(to, reached); ++id)
      if (auto it = byId.find(static_cast<std::int64_t>(id)); it != byId.end())
        ms.push_back(it->second->inspectionMs);
    r.baselineP99Ms = quantile(ms, 0.99);
  }
  judge(o, r);
  if (timedOut)
    r.failures.insert(r.failures.begin(), "timed out after " + std::to_string(o.timeout.count()) +
                                              " s at part " + std::to_string(reached));
  return r;
}

void printSoakReport(std::ostream& out, const SoakOptions& o, const SoakReport& r) {
  char line[512];
  out << "facetd soak: " << o.parts << " parts, recipe " << o.recipe << ", replay of "
      << o.replayFolder << " (looped), free run, no PLC, archive keep=fail quota "
      << o.archiveQuotaMb << " MB\n";
  out << "RSS: peak of the window's samples; fds, threads: fewest sampled (max fds in brackets);\n"
      << "p50/p99: inspection ms per part from the results database; publish p99: histogram "
         "bucket bound (ms)\n";
  std::snprintf(line, sizeof line, "%-7s %-15s %8s %8s %10s %8s %8s %8s %12s\n", "window", "parts",
                "s", "RSS MiB", "fds", "threads", "p50 ms", "p99 ms", "publish p99");
  out << line;
  for (std::size_t k = 0; k < r.windows.size(); ++k) {
    const auto& w = r.windows[k];
    const std::string name =
        std::to_string(k + 1) + (static_cast<int>(k) < o.warmupWindows ? " warm" : "");
    const std::string range = std::to_string(w.firstPart) + "-" + std::to_string(w.lastPart);
    const std::string fds = std::to_string(w.fds) + " (" + std::to_string(w.maxFds) + ")";
    std::snprintf(line, sizeof line, "%-7s %-15s %8.1f %8.1f %10s %8d %8.2f %8.2f %12.4g\n",
                  name.c_str(), range.c_str(), w.seconds, w.rssMiB, fds.c_str(), w.threads, w.p50Ms,
                  w.p99Ms, w.publishP99Ms);
    out << line;
  }
  std::snprintf(line, sizeof line,
                "stored %llu parts in %.0f s (facetd exit %d); missing ids %llu, not inspected "
                "%llu, unexpected verdicts %llu; integrity_check %s; database %.1f MiB; archive "
                "%llu files, %.1f MiB (quota %.0f)\n",
                static_cast<unsigned long long>(r.partsStored), r.seconds, r.exitCode,
                static_cast<unsigned long long>(r.partsMissing),
                static_cast<unsigned long long>(r.errorParts),
                static_cast<unsigned long long>(r.unexpected), r.integrity.c_str(), r.databaseMiB,
                static_cast<unsigned long long>(r.archiveFiles), r.archiveMiB, o.archiveQuotaMb);
  out << line;
  std::snprintf(line, sizeof line,
                "baseline: windows %d-%d (highest RSS %.1f MiB, fds %d, threads %d; inspection "
                "p99 over their parts %.2f ms)\n",
                o.warmupWindows + 1, o.warmupWindows + o.baselineWindows, r.baselineRssMiB,
                r.baselineFds, r.baselineThreads, r.baselineP99Ms);
  out << line;
  std::snprintf(line, sizeof line,
                "last window vs baseline: RSS %+.2f %% (bound %.1f %%), fds %+d (bound %d), "
                "threads %+d (bound %d), inspection p99 x%.2f (%s)\n",
                100 * r.rssGrowth, 100 * o.maxRssGrowth, r.fdGrowth, o.maxFdGrowth, r.threadGrowth,
                o.maxThreadGrowth, r.p99Ratio,
                o.maxP99Ratio > 0 ? ("bound x" + std::to_string(o.maxP99Ratio).substr(0, 4) +
                                     "; timing on a shared machine is noisy")
                                        .c_str()
                                  : "not judged");
  out << line;
  if (r.ok()) {
    out << "verdict: PASS\n";
  } else {
    out << "verdict: FAIL\n";
    for (const auto& f : r.failures) out << "  " << f << "\n";
  }
}

}  // namespace facet::soak
