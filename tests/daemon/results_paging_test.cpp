// A client (an MES, a script) pages through facetd's results over HTTP while parts keep
// arriving: GET /api/results?after=N&limit=50, then again after the last id it got. It must see
// every stored part exactly once, in order, however many parts arrived between two of its calls.
#include <gtest/gtest.h>

#include <csignal>
#include <cstdio>
#include <filesystem>
#include <map>
#include <thread>

#include "tests/daemon/child_process.hpp"
#include "tests/daemon/facetd_http.hpp"
#include "tests/daemon/line_run.hpp"

namespace facet::daemon_test {
namespace {

using namespace std::chrono_literals;
using Clock = std::chrono::steady_clock;
namespace fs = std::filesystem;

constexpr int kParts = 400;
constexpr int kPageSize = 50;
const std::string kDemo = std::string(FACET_SOURCE_DIR) + "/recipes/demo/bracket_shape";

// `count` images part_0000.png ...: the 12 demo images over and over, as symbolic links.
std::string linkImages(const TempDir& dir, int count) {
  const fs::path folder = dir / "images";
  fs::create_directory(folder);
  for (int i = 0; i < count; ++i) {
    char name[32];
    std::snprintf(name, sizeof name, "part_%04d.png", i);
    char demo[32];
    std::snprintf(demo, sizeof demo, "part_%03d.png", i % 12);
    fs::create_symlink(fs::path(kDemo) / demo, folder / name);
  }
  return folder.string();
}

// The part ids of one page; nullopt when facetd did not answer with a page.
std::optional<std::vector<std::int64_t>> page(int port, std::int64_t after) {
  const auto body = httpGet(
      port, "/api/results?after=" + std::to_string(after) + "&limit=" + std::to_string(kPageSize));
  if (!body) return std::nullopt;
  const auto json = nlohmann::json::parse(*body, nullptr, false);
  if (!json.contains("parts")) return std::nullopt;
  std::vector<std::int64_t> ids;
  for (const auto& p : json.at("parts")) ids.push_back(p.at("part_id").get<std::int64_t>());
  return ids;
}

std::int64_t partsInspected(int port) {
  const auto metrics = httpGet(port, "/metrics").value_or("");
  double n = 0;
  for (const char* verdict : {"pass", "fail", "error"})
    n += metricValue(metrics, std::string("facet_parts_total{verdict=\"") + verdict + "\"}")
             .value_or(0);
  return static_cast<std::int64_t>(n);
}

TEST(ResultsPaging, PagesOfFiftyGetEveryPartOnceWhilePartsArrive) {
  TempDir dir;
  const std::string images = linkImages(dir, kParts);
  // A free-running camera at 100 parts/s; the run takes about 4 s.
  const std::string station =
      writeStationFile(dir.path(),
                       "  backend: replay\n  replay:\n    folder: " + images +
                           "\n    glob: \"*.png\"\n    loop: false\n    fps: 100\n"
                           "    trigger: free_run\n    colour: mono\n",
                       0, {.archiveKeep = "none"});
  ChildProcess facetd(
      {FACETD_PATH, "--config", station, "--recipe", "2", "--no-plc", "--block-when-behind",
       "--http-port-file", dir / "http.port", "--log-level", "warn"},
      {}, dir / "facetd.log");
  const auto port = waitForHttpPort(dir / "http.port", 30s);
  ASSERT_TRUE(port) << "facetd did not start\n" << facetd.outputTail();

  // The client: a full page is followed at once by the next; after a short page it waits until
  // more than two pages' worth of parts have arrived, so that every call finds a backlog larger
  // than its page.
  std::vector<std::int64_t> received;
  std::int64_t after = 0;
  int pages = 0, backlogs = 0;
  // The run takes as long as the inspections do (4 s here, minutes under a sanitizer): the
  // client gives up only when no part has been inspected for 30 s.
  std::int64_t inspected = 0;
  auto progressAt = Clock::now();
  const auto stalled = [&] {
    const std::int64_t now = partsInspected(*port);
    if (now != inspected) {
      inspected = now;
      progressAt = Clock::now();
    }
    return Clock::now() - progressAt > 30s;
  };
  while (received.size() < static_cast<std::size_t>(kParts) && !stalled()) {
    const auto ids = page(*port, after);
    ASSERT_TRUE(ids) << "no page after part " << after << "\n" << facetd.outputTail();
    ++pages;
    for (const auto id : *ids) {
      ASSERT_GT(id, after) << "page after " << after << " is not in ascending order past it";
      after = id;
      received.push_back(id);
    }
    if (ids->size() == static_cast<std::size_t>(kPageSize)) {
      ++backlogs;
      continue;
    }
    // The run is over and the store has nothing after the last id: whatever is missing now
    // was lost.
    if (ids->empty() && partsInspected(*port) >= kParts) break;
    const std::int64_t waitFor = std::min<std::int64_t>(kParts, after + 2 * kPageSize + 10);
    while (inspected < waitFor && !stalled()) std::this_thread::sleep_for(20ms);
    std::this_thread::sleep_for(50ms);  // the store is written just after the count
  }
  ASSERT_EQ(page(*port, after), std::optional(std::vector<std::int64_t>{}))
      << "parts after the last one the client saw";
  facetd.signal(SIGTERM);
  ASSERT_EQ(facetd.wait(20s), std::optional<int>(0)) << facetd.outputTail();

  // The store, read through a connection of the test's own, holds what the client received.
  std::vector<std::int64_t> stored;
  for (const auto& p : storedParts(dir / "results.db")) stored.push_back(p.partId);
  ASSERT_EQ(stored.size(), static_cast<std::size_t>(kParts)) << "parts missing from the store";
  EXPECT_EQ(received, stored) << "after " << pages << " pages";
  std::map<std::int64_t, int> times;
  for (const auto id : received) ++times[id];
  for (const auto& [id, n] : times) EXPECT_EQ(n, 1) << "part " << id;
  // The client did meet a backlog larger than a page many times (2 full pages per wait).
  EXPECT_GE(backlogs, kParts / (3 * kPageSize));
}

}  // namespace
}  // namespace facet::daemon_test
