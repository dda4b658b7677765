// facetd on a line whose PLC loses power three times during a 1,000-part run. The camera free
// runs (a replay of 1,000 recorded images at a line rate) and the PLC link runs the free-run
// handshake, so parts keep coming while the PLC is away: the results wait in the link's queue,
// and those that do not fit are dropped. The pymodbus PLC reports every write of the inspection
// counter as it lands, so the test knows exactly which parts reached it; facetd's log and
// /metrics say which did not. Every part must be in one of the two sets, and in the store.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <filesystem>
#include <map>
#include <regex>
#include <set>
#include <thread>

#include "tests/daemon/child_process.hpp"
#include "tests/daemon/facetd_http.hpp"
#include "tests/daemon/line_run.hpp"
#include "tests/plc/pymodbus_peer.hpp"

namespace facet::daemon_test {
namespace {

using namespace std::chrono_literals;
using Clock = std::chrono::steady_clock;
namespace fs = std::filesystem;

constexpr int kParts = 1000;
constexpr int kQueueCapacity = 24;  // about 0.6 s of parts at the replay rate
// The issue's bound. An instrumented (ASan) facetd on a loaded CI machine gets twice that: the
// policy (backoff capped at 500 ms) is the same, only the machine is slower.
#if defined(__SANITIZE_ADDRESS__)
constexpr double kReconnectBoundMs = 2000.0;
#else
constexpr double kReconnectBoundMs = 1000.0;
#endif
const std::string kDemo = std::string(FACET_SOURCE_DIR) + "/recipes/demo/bracket_shape";

// `count` images named part_0000.png ... (with their sidecars): the 12 demo images over and
// over, as symbolic links. The replay reads each once and then waits: the run ends by itself.
std::string linkImages(const TempDir& dir, int count) {
  const fs::path folder = dir / "images";
  fs::create_directory(folder);
  for (int i = 0; i < count; ++i) {
    char name[32];
    std::snprintf(name, sizeof name, "part_%04d.png", i);
    char demo[32];
    std::snprintf(demo, sizeof demo, "part_%03d.png", i % 12);
    fs::create_symlink(fs::path(kDemo) / demo, folder / name);
    fs::create_symlink(fs::path(kDemo) / (std::string(demo) + ".json"),
                       folder / (std::string(name) + ".json"));
  }
  return folder.string();
}

// Part ids named by the log lines matching `pattern` (first capture group).
std::multiset<std::int64_t> partsLogged(const std::string& log, const std::regex& pattern) {
  std::multiset<std::int64_t> ids;
  for (std::sregex_iterator it(log.begin(), log.end(), pattern), end; it != end; ++it)
    ids.insert(std::stoll((*it)[1].str()));
  return ids;
}

// Milliseconds between two of the PLC's time stamps (seconds of CLOCK_MONOTONIC).
double millisecondsBetween(double from, double to) {
  return (to - from) * 1000.0;
}

TEST(PlcOutage, ThreeRestartsDuringAThousandPartRun) {
  TempDir dir;
  const std::string images = linkImages(dir, kParts);
  const int plcPort = plc::test::freeTcpPort();
  // 40 parts/s: the whole run takes about 25 s. No reconnect settings: the defaults are tested.
  const std::string station = writeStationFile(
      dir.path(),
      "  backend: replay\n  replay:\n    folder: " + images +
          "\n    glob: \"*.png\"\n    loop: false\n    fps: 40\n    trigger: free_run\n"
          "    colour: mono\n",
      plcPort,
      {.plcMode = "free_run",
       .plcExtra = "  queue_capacity: " + std::to_string(kQueueCapacity) + "\n"});
  const std::string peerConfig = writePeerConfig(station, /*freeRun=*/true);
  plc::test::PymodbusPlc plc(peerConfig, plcPort);
  plc.start();

  ChildProcess facetd({FACETD_PATH, "--config", station, "--recipe", "2", "--http-port-file",
                       dir / "http.port", "--log-level", "info"},
                      {}, dir / "facetd.log");
  const auto httpPort = waitForHttpPort(dir / "http.port", 30s);
  ASSERT_TRUE(httpPort) << "facetd did not start\n" << facetd.outputTail();

  // Holds once the PLC has seen an inspection counter of at least `counter`.
  auto seenUpTo = [&](int counter) {
    return [counter](const std::vector<nlohmann::json>& events) {
      for (const auto& e : events)
        if (e.value("event", "") == "result" && e.value("counter", 0) >= counter) return true;
      return false;
    };
  };
  auto firstWrites = [](std::size_t n) {
    return [n](const std::vector<nlohmann::json>& events) {
      return static_cast<std::size_t>(std::count_if(events.begin(), events.end(), [](auto& e) {
               return e.value("event", "") == "first_write";
             })) >= n;
    };
  };

  // Three power cuts of different lengths, spread over the run.
  const int killAt[] = {150, 430, 700};
  const std::chrono::milliseconds outage[] = {1000ms, 1700ms, 2500ms};
  std::vector<double> reconnectMs, killedAt, listeningAt;
  for (int k = 0; k < 3; ++k) {
    ASSERT_TRUE(plc.waitFor(seenUpTo(killAt[k]), 60s))
        << "the PLC never saw inspection counter " << killAt[k];
    killedAt.push_back(std::chrono::duration<double>(Clock::now().time_since_epoch()).count());
    plc.kill();
    std::this_thread::sleep_for(outage[k]);
    plc.start();
    const double listening = plc.events("listening").back().at("t").get<double>();
    listeningAt.push_back(listening);
    ASSERT_TRUE(plc.waitFor(firstWrites(static_cast<std::size_t>(k) + 2), 10s))
        << "facetd did not come back to the PLC within 10 s of restart " << k + 1;
    const double firstWrite = plc.events("first_write").back().at("t").get<double>();
    reconnectMs.push_back(millisecondsBetween(listening, firstWrite));
  }

  // The replay ends after kParts images; wait until every part is stored and the PLC queue is
  // empty, so that the counts read from /metrics are final.
  std::string metrics;
  const auto until = Clock::now() + 90s;
  bool settled = false;
  while (!settled && Clock::now() < until) {
    std::this_thread::sleep_for(200ms);
    metrics = httpGet(*httpPort, "/metrics").value_or("");
    const auto parts = metricValue(metrics, "facet_parts_total{verdict=\"pass\"}").value_or(0) +
                       metricValue(metrics, "facet_parts_total{verdict=\"fail\"}").value_or(0) +
                       metricValue(metrics, "facet_parts_total{verdict=\"error\"}").value_or(0);
    settled = parts >= kParts &&
              metricValue(metrics, "facet_queue_depth{queue=\"plc\"}") == std::optional(0.0) &&
              metricValue(metrics, "facet_plc_connected") == std::optional(1.0);
  }
  ASSERT_TRUE(settled) << "the run did not settle; last /metrics:\n" << metrics;
  facetd.signal(SIGTERM);
  ASSERT_EQ(facetd.wait(20s), std::optional<int>(0)) << facetd.outputTail();

  // The store: every part, once, ids 1..kParts.
  const auto stored = storedParts(dir / "results.db");
  ASSERT_EQ(stored.size(), static_cast<std::size_t>(kParts)) << "parts missing from the store";
  for (std::size_t i = 0; i < stored.size(); ++i)
    ASSERT_EQ(stored[i].partId, static_cast<std::int64_t>(i) + 1);
  EXPECT_EQ(integrityCheck(dir / "results.db"), "ok");

  // Delivered: the inspection counters the PLC saw written (a fresh store: part id = counter).
  // A result written again after a reconnect carries the same counter and the same content.
  std::map<int, nlohmann::json> delivered;
  int repeats = 0;
  for (const auto& e : plc.events("result")) {
    const int counter = e.at("counter").get<int>();
    ASSERT_GE(counter, 1);
    ASSERT_LE(counter, kParts) << "a counter no part has";
    auto [it, fresh] = delivered.emplace(counter, e);
    if (fresh) continue;
    ++repeats;
    EXPECT_EQ(it->second.at("pass"), e.at("pass")) << "counter " << counter;
    EXPECT_EQ(it->second.at("error"), e.at("error")) << "counter " << counter;
    // An error result leaves the value registers as they were: only a measured repeat must
    // carry the same values.
    if (!e.at("error").get<bool>()) {
      EXPECT_EQ(it->second.at("values"), e.at("values")) << "counter " << counter;
    }
  }

  // Undelivered: dropped from the full queue (logged by the link and by the station, counted in
  // facet_plc_dropped_results), or abandoned at the stop (logged; none expected here).
  std::string log;  // facetd logs on stdout
  for (const auto& line : facetd.lines()) log += line + "\n";
  const auto dropped =
      partsLogged(log, std::regex(R"(result of part '(\d+)' \(inspection counter \d+\) dropped)"));
  const auto droppedByStation =
      partsLogged(log, std::regex(R"(part (\d+) recipe 2: result not delivered to the PLC)"));
  const auto abandoned =
      partsLogged(log, std::regex(R"(result of part '(\d+)' \(inspection counter \d+\) not)"));
  EXPECT_EQ(dropped, droppedByStation);
  EXPECT_EQ(metricValue(metrics, "facet_plc_dropped_results"),
            std::optional(static_cast<double>(dropped.size())));
  EXPECT_TRUE(abandoned.empty()) << abandoned.size() << " results abandoned at a clean stop";

  std::set<std::int64_t> undelivered(dropped.begin(), dropped.end());
  undelivered.insert(abandoned.begin(), abandoned.end());
  EXPECT_EQ(undelivered.size(), dropped.size() + abandoned.size()) << "a part logged twice";
  int passes = 0, errors = 0;
  for (const auto& part : stored) {
    errors += part.verdict == "error";
    const auto found = delivered.find(static_cast<int>(part.partId));
    const bool wasDelivered = found != delivered.end();
    const bool wasUndelivered = undelivered.count(part.partId) > 0;
    EXPECT_NE(wasDelivered, wasUndelivered)
        << "part " << part.partId
        << (wasDelivered ? " delivered and logged as undelivered"
                         : " neither delivered nor logged");
    if (!wasDelivered) continue;
    // What the PLC was told is what was found: never "good" for a part not inspected good.
    const auto& r = found->second;
    EXPECT_EQ(r.at("pass").get<bool>(), part.verdict == "pass") << "part " << part.partId;
    EXPECT_EQ(r.at("error").get<bool>(), part.verdict == "error") << "part " << part.partId;
    EXPECT_EQ(r.at("error_code").get<int>() != 0, part.verdict == "error")
        << "part " << part.partId;
    passes += part.verdict == "pass";
    const auto& values = r.at("values");
    if (part.verdict == "error") {
      // Nothing measured: the outputs read "not measured" (float NaN, integers 0), never the
      // previous part's values.
      EXPECT_TRUE(values.at("bore_to_edge.distance").is_null()) << "part " << part.partId;
      EXPECT_EQ(values.at("label.count").get<double>(), 0.0) << "part " << part.partId;
      continue;
    }
    const auto& m = part.measurements;
    ASSERT_TRUE(m.count("label.count") && m.count("bore_to_edge.distance"))
        << "part " << part.partId << " lacks a measurement";
    EXPECT_EQ(values.at("label.count").get<double>(), std::round(m.at("label.count").value))
        << "part " << part.partId;
    EXPECT_FLOAT_EQ(values.at("bore_to_edge.distance").get<float>(),
                    static_cast<float>(m.at("bore_to_edge.distance").value))
        << "part " << part.partId;
  }
  EXPECT_EQ(delivered.size() + undelivered.size(), static_cast<std::size_t>(kParts));
  // The outages outlast the queue (about 0.6 s of parts): some results had to be dropped.
  EXPECT_GT(dropped.size(), 0u);
  EXPECT_GT(passes, 0);

  // The daemon was back within 1 s of the PLC's return each time (PLC listening -> the PLC sees
  // the daemon's first write). It connected at least once per PLC start; sometimes once more:
  // a connect can land in the backlog of the dying PLC's listening socket, which the kernel
  // closes just after the connections (the link then sees the reset and tries again).
  for (int k = 0; k < 3; ++k)
    EXPECT_LT(reconnectMs[k], kReconnectBoundMs)
        << "reconnect after restart " << k + 1 << "; PLC kill at " << killedAt[k]
        << " s, listening at " << listeningAt[k] << " s (CLOCK_MONOTONIC)";
  EXPECT_GE(metricValue(metrics, "facet_plc_reconnects").value_or(0), 4.0);

  std::cout << "[ figures  ] parts " << kParts << " (" << errors << " not inspected), delivered "
            << delivered.size() << " (repeats " << repeats << "), undelivered "
            << undelivered.size() << " (dropped " << dropped.size() << ", abandoned "
            << abandoned.size() << "), reconnect ms " << reconnectMs[0] << " / " << reconnectMs[1]
            << " / " << reconnectMs[2] << ", connects "
            << metricValue(metrics, "facet_plc_reconnects").value_or(0) << "\n";
  if (HasFailure()) {  // the link's story (queue overflow lines left out)
    std::cout << "facetd's PLC log:\n";
    for (const auto& line : facetd.lines())
      if ((line.find("PLC") != std::string::npos || line.find("Modbus") != std::string::npos) &&
          line.find("queue full") == std::string::npos &&
          line.find("(queue full)") == std::string::npos)
        std::cout << line << "\n";
    for (const auto& e : plc.events("listening")) std::cout << e.dump() << "\n";
    for (const auto& e : plc.events("first_write")) std::cout << e.dump() << "\n";
  }
  std::error_code ignored;
  fs::remove(peerConfig, ignored);
}

}  // namespace
}  // namespace facet::daemon_test
