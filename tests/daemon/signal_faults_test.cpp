// facetd stopped by the service manager at a bad moment. SIGTERM while a part is being
// inspected: that part is finished, stored and sent to the PLC (not aborted, not dropped), then
// facetd exits 0.
// SIGKILL, several times at arbitrary moments of a fast run: each time the SQLite store is sound
// (PRAGMA integrity_check), still in WAL mode, keeps every committed row, and the restarted
// daemon continues the part ids without a gap or a repeat. (daemon_systemd_test's
// KillThenRestartContinuesPartIds covers one kill of a slow run.)
#include <gtest/gtest.h>

#include <csignal>
#include <filesystem>
#include <random>
#include <set>
#include <thread>

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>

#include "tests/daemon/child_process.hpp"
#include "tests/daemon/line_run.hpp"
#include "tests/plc/pymodbus_peer.hpp"

namespace facet::daemon_test {
namespace {

using namespace std::chrono_literals;
using Clock = std::chrono::steady_clock;
namespace fs = std::filesystem;

const std::string kDemo = std::string(FACET_SOURCE_DIR) + "/recipes/demo/bracket_shape";

std::string replayCamera(const std::string& folder, double fps) {
  return "  backend: replay\n  replay:\n    folder: " + folder +
         "\n    glob: \"*.png\"\n    loop: true\n    fps: " + std::to_string(fps) +
         "\n    trigger: free_run\n    colour: mono\n";
}

std::unique_ptr<ChildProcess> startFacetd(const TempDir& dir, const std::string& station,
                                          const std::string& logLevel, bool withPlc = false) {
  std::vector<std::string> argv{FACETD_PATH, "--config",    station, "--recipe",
                                "2",         "--log-level", logLevel};
  if (!withPlc) argv.push_back("--no-plc");
  return std::make_unique<ChildProcess>(std::move(argv), std::map<std::string, std::string>{},
                                        dir / "facetd.log");
}

// Index of the first stdout line containing `text`, or -1.
long lineIndex(const std::vector<std::string>& lines, const std::string& text) {
  for (std::size_t i = 0; i < lines.size(); ++i)
    if (lines[i].find(text) != std::string::npos) return static_cast<long>(i);
  return -1;
}

std::size_t storedCount(const std::string& database) {
  try {
    return fs::exists(database) ? storedParts(database).size() : 0;
  } catch (const std::exception&) {
    return 0;  // facetd has created the file but not yet its tables
  }
}

bool waitForCount(const std::string& database, std::size_t n, std::chrono::seconds timeout) {
  const auto until = Clock::now() + timeout;
  while (Clock::now() < until) {
    if (storedCount(database) >= n) return true;
    std::this_thread::sleep_for(20ms);
  }
  return false;
}

TEST(SignalFaults, SigtermDuringAPartFinishesAndStoresIt) {
  TempDir dir;
  // A slow part: a demo image in the middle of an 8000 x 8000 background (the shape search
  // covers the whole frame: several hundred ms per part, where the demo image takes ~8 ms).
  const fs::path images = dir / "images";
  fs::create_directory(images);
  for (int i = 0; i < 2; ++i) {
    const cv::Mat part =
        cv::imread(kDemo + "/part_00" + std::to_string(i) + ".png", cv::IMREAD_GRAYSCALE);
    ASSERT_FALSE(part.empty());
    cv::Mat big(8000, 8000, CV_8UC1, cv::Scalar(part.at<std::uint8_t>(0, 0)));
    part.copyTo(big(cv::Rect(3600, 3700, part.cols, part.rows)));
    ASSERT_TRUE(cv::imwrite((images / ("part_00" + std::to_string(i) + ".png")).string(), big));
  }
  // A free-run PLC that reports every result as it lands: the finished part must reach it too.
  const int plcPort = plc::test::freeTcpPort();
  const auto station =
      writeStationFile(dir.path(), replayCamera(images, 2), plcPort,
                       // Scale only: the example station's lens model is for 640x480 frames.
                       {.plcMode = "free_run", .calibration = "  mm_per_pixel: 0.05\n"});
  const std::string peerConfig = writePeerConfig(station, /*freeRun=*/true);
  plc::test::PymodbusPlc plc(peerConfig, plcPort);
  plc.start();
  auto facetd = startFacetd(dir, station, "debug", /*withPlc=*/true);

  // How long one part takes here (a fraction of a second, far more under a sanitizer): facetd
  // is given that long per part it may be finishing, plus 30 s, to exit after SIGTERM.
  const auto lineOf = [&](const std::string& text) {
    return facetd->waitForLine(
        [&](const std::string& l) { return l.find(text) != std::string::npos; }, 300s);
  };
  ASSERT_TRUE(lineOf("part=1 inspecting ")) << "no part inspected\n" << facetd->outputTail();
  const auto firstBegan = Clock::now();
  ASSERT_TRUE(lineOf("part=1 recipe=2 verdict=")) << "part 1 not finished\n"
                                                  << facetd->outputTail();
  const auto perPart = Clock::now() - firstBegan;

  // A part after the first has begun its inspection. (When the inspection is slower than the
  // camera, as under a sanitizer, parts in between are dropped as missed: any id >= 2 will do.)
  const auto startedLine = facetd->waitForLine(
      [](const std::string& l) {
        const auto at = l.find("part=");
        return l.find(" inspecting ") != std::string::npos && at != std::string::npos &&
               std::stoll(l.substr(at + 5)) >= 2;
      },
      120s);
  ASSERT_TRUE(startedLine) << "no second part inspected\n" << facetd->outputTail();
  facetd->signal(SIGTERM);
  const auto partId = std::stoll(startedLine->substr(startedLine->find("part=") + 5));
  const std::string part = "part " + std::to_string(partId);
  // The part in inspection and, at most, the one the camera handed over just before.
  const auto allowed = std::chrono::duration_cast<std::chrono::milliseconds>(30s + 2 * perPart);
  const auto code = facetd->wait(allowed);
  ASSERT_TRUE(code.has_value())
      << "facetd did not exit within " << allowed.count() << " ms of SIGTERM (one part took "
      << std::chrono::duration_cast<std::chrono::milliseconds>(perPart).count() << " ms)";
  EXPECT_EQ(*code, 0);

  // SIGTERM arrived while that part was inspected: the log says so before the part's verdict.
  const auto lines = facetd->lines();
  const long term = lineIndex(lines, "SIGTERM: finishing the parts in progress");
  const long verdict = lineIndex(lines, "part=" + std::to_string(partId) + " recipe=2 verdict=");
  ASSERT_GE(term, 0) << "facetd did not log the SIGTERM";
  ASSERT_GE(verdict, 0) << part << " has no verdict in the log";
  EXPECT_LT(term, verdict) << part << " was already finished when SIGTERM came: not a test of it";

  // That part is stored, finished (a real verdict, not an abort), and so is every part taken.
  const auto parts = storedParts(dir / "results.db");
  ASSERT_GE(parts.size(), static_cast<std::size_t>(partId));
  for (std::size_t i = 0; i < parts.size(); ++i)
    EXPECT_EQ(parts[i].partId, static_cast<std::int64_t>(i) + 1) << "part ids have a hole";
  const auto& finished = parts[static_cast<std::size_t>(partId) - 1];
  EXPECT_EQ(finished.verdict, "pass") << part << ": " << finished.error;
  EXPECT_GE(finished.measurements.size(), 4u) << part;
  for (const auto& l : lines) {  // every part whose inspection began was stored
    const auto at = l.find(" inspecting ");
    if (l.find("part=") == std::string::npos || at == std::string::npos) continue;
    const auto id = std::stoll(l.substr(l.find("part=") + 5));
    EXPECT_LE(id, static_cast<long long>(parts.size())) << "part " << id << " began, not stored";
  }
  EXPECT_EQ(integrityCheck(dir / "results.db"), "ok");

  // ... and every stored part, the one finished after SIGTERM included, reached the PLC before
  // facetd let go of the link.
  // (The peer printed each result before answering its write; the pipe may still hold some.)
  const int lastPart = static_cast<int>(parts.back().partId);
  plc.waitFor(
      [&](const std::vector<nlohmann::json>& events) {
        for (const auto& e : events)
          if (e.value("event", "") == "result" && e.value("counter", 0) == lastPart) return true;
        return false;
      },
      5s);
  std::set<int> counters;
  for (const auto& e : plc.events("result")) counters.insert(e.at("counter").get<int>());
  for (const auto& p : parts)
    EXPECT_TRUE(counters.count(static_cast<int>(p.partId))) << "part " << p.partId << " not sent";
  std::error_code ignored;
  fs::remove(peerConfig, ignored);
}

TEST(SignalFaults, RepeatedSigkillKeepsTheStoreSoundInWalAndPartIdsContinue) {
  TempDir dir;
  // As fast as the demo images go: the store commits a part every few milliseconds, so a kill
  // very likely lands in the middle of a transaction or with the WAL not yet checkpointed.
  const auto station = writeStationFile(dir.path(), replayCamera(kDemo, 0), 0);
  const std::string database = dir / "results.db";
  std::mt19937 random(12);  // fixed: the same kill moments every run, relative to the parts
  std::vector<StoredPart> before;
  int walLeftBehind = 0;
  for (int round = 0; round < 3; ++round) {
    auto facetd = startFacetd(dir, station, "warn");
    ASSERT_TRUE(waitForCount(database, before.size() + 30, 60s))
        << "round " << round << ": facetd stores no parts\n"
        << facetd->outputTail();
    std::this_thread::sleep_for(std::chrono::milliseconds(random() % 200));
    facetd->signal(SIGKILL);
    ASSERT_EQ(facetd->wait(10s), std::optional<int>(128 + SIGKILL));

    // What a restarted daemon finds, before it opens the file.
    std::error_code ec;
    const auto wal = fs::file_size(database + "-wal", ec);
    walLeftBehind += !ec && wal > 0;
    ASSERT_EQ(integrityCheck(database), "ok") << "round " << round;
    EXPECT_EQ(journalMode(database), "wal") << "round " << round;
    const auto after = storedParts(database);
    ASSERT_GE(after.size(), before.size() + 30);
    for (std::size_t i = 0; i < after.size(); ++i) {
      // Ids 1..N: each run continued after the last stored part, and stored in order.
      ASSERT_EQ(after[i].partId, static_cast<std::int64_t>(i) + 1) << "round " << round;
      if (i < before.size()) {  // committed rows survive the kill unchanged
        EXPECT_EQ(after[i].verdict, before[i].verdict) << "part " << i + 1;
        EXPECT_EQ(after[i].frameId, before[i].frameId) << "part " << i + 1;
        EXPECT_EQ(after[i].measurements.size(), before[i].measurements.size()) << "part " << i + 1;
      }
    }
    before = after;
  }

  // A last clean run continues after the last part of the third kill.
  auto facetd = startFacetd(dir, station, "warn");
  ASSERT_TRUE(waitForCount(database, before.size() + 10, 60s));
  facetd->signal(SIGTERM);
  EXPECT_EQ(facetd->wait(20s), std::optional<int>(0));
  const auto last = storedParts(database);
  for (std::size_t i = 0; i < last.size(); ++i)
    ASSERT_EQ(last[i].partId, static_cast<std::int64_t>(i) + 1);
  EXPECT_EQ(integrityCheck(database), "ok");
  EXPECT_EQ(journalMode(database), "wal");
  std::cout << "[ figures  ] " << before.size() << " parts over 3 kills (WAL left behind by "
            << walLeftBehind << " of them), " << last.size() << " after the clean run\n";
}

}  // namespace
}  // namespace facet::daemon_test
