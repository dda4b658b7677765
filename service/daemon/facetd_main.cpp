// facetd: the inspection daemon. See station.hpp for the stages and http_server.hpp for the
// HTTP endpoints. Signals: SIGHUP reloads the recipes; SIGTERM/SIGINT finish the parts in
// progress, flush the results and exit 0. runFacetd() is the whole program for a set of step
// kinds; facetd.cpp runs it with facet's own (a test adds a kind of its own).
#include <csignal>
#include <fstream>
#include <iostream>
#include <thread>

#include <spdlog/spdlog.h>
#include <CLI/CLI.hpp>

#include "service/daemon/calibration_check.hpp"
#include "service/daemon/facetd_main.hpp"
#include "service/daemon/http_server.hpp"
#include "service/daemon/part_banner.hpp"
#include "service/daemon/station.hpp"
#include "service/daemon/systemd_notifier.hpp"
#include "service/sinks/fleet_publishers.hpp"
#include "service/sinks/fleet_station_view.hpp"

namespace {

using namespace facet;
using namespace std::chrono_literals;

// One line per part for --print-parts, never cut: the verdict, why (each failed check with its
// value and band, or the error of a part that was not inspected), what the recording says the
// part was (its sidecar's verdict and defect, flagged UNEXPECTED when the verdicts differ), then
// every measured value, "(!)" marking a value outside its tolerance band, and the time.
std::string partLine(const service::PartResult& p) {
  std::string line = "part " + std::to_string(p.partId) + "  recipe " + std::to_string(p.recipeId) +
                     " " + p.recipeName + (p.serial.empty() ? "" : "  " + p.serial) + "  " +
                     service::verdictName(p.verdict);
  if (p.verdict == service::Verdict::Error) {
    line += "  cause: " + p.error;
  } else if (!p.failedChecks.empty()) {
    line += "  cause:";
    for (std::size_t i = 0; i < p.failedChecks.size(); ++i)
      line += (i ? "; " : " ") + service::failedCheckText(p, p.failedChecks[i]);
  }
  if (!p.expectedVerdict.empty()) {
    line += "  recorded: " + p.expectedVerdict;
    if (!p.recordedDefect.empty()) line += " (" + p.recordedDefect + ")";
    if (p.expectedVerdict != service::verdictName(p.verdict)) line += "  UNEXPECTED";
  }
  if (p.verdict != service::Verdict::Error && !p.measurements.empty()) {
    line += "  values:";
    for (const auto& m : p.measurements) {
      char value[32];
      std::snprintf(value, sizeof value, "%.4g", m.value);
      line += " " + m.name + "=" + value +
              (m.unit == "score" || m.unit == "count" ? "" : " " + m.unit) + (m.pass ? "" : "(!)");
    }
  }
  char ms[32];
  std::snprintf(ms, sizeof ms, "  [%.1f ms]", p.inspectionMs);
  return line + ms;
}

// --replay: the folder's images replace the configured camera; a folder of range scans replaces
// the scan replay. Each file is replayed once, as fast as the station takes it.
void useReplay(config::StationConfig& station, const std::filesystem::path& folder) {
  bool scans = false;
  for (const auto& entry : std::filesystem::directory_iterator(folder))
    if (entry.path().extension() == ".csv") scans = true;
  if (scans) {
    station.camera.scans.folder = std::filesystem::absolute(folder);
    station.camera.scans.glob = "*.csv";
    return;
  }
  station.camera.backend = CameraBackend::Replay;
  station.camera.replay.folder = std::filesystem::absolute(folder);
  station.camera.replay.glob.clear();
  station.camera.replay.loop = false;
  station.camera.replay.fps = 0;
}

}  // namespace

int facet::service::runFacetd(int argc, char** argv, const config::StepKindRegistry& kinds) {
  CLI::App app{"facetd: the facet inspection daemon", "facetd"};
  std::string configFile, logLevel = "info", portFile, replayFolder;
  std::optional<int> recipe;
  std::uint64_t maxParts = 0;
  bool exitAtEnd = false, printParts = false, noPlc = false, blockWhenBehind = false;
  app.add_option("--config", configFile, "Station config (YAML)")->required();
  app.add_option("--recipe", recipe, "Recipe id to start with (default: the lowest)");
  app.add_option("--max-parts", maxParts, "Stop after this many parts (0 = run until stopped)");
  app.add_flag("--exit-at-end", exitAtEnd,
               "Replay without loop: exit once every file is inspected");
  app.add_flag("--print-parts", printParts, "Print one line per part on stdout, and a summary");
  app.add_flag("--no-plc", noPlc, "Run without the PLC link");
  app.add_flag(
      "--block-when-behind", blockWhenBehind,
      "Hold the trigger back instead of dropping the oldest frame when inspection falls behind");
  app.add_option("--replay", replayFolder,
                 "Replay this recorded folder once instead of the configured camera (images, or "
                 "*.csv range scans for scan recipes); implies --exit-at-end")
      ->check(CLI::ExistingDirectory);
  app.add_option("--http-port-file", portFile, "Write the HTTP port here once listening");
  app.add_option("--log-level", logLevel, "trace, debug, info, warn, error");
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    if (e.get_exit_code() == 0) return app.exit(e);  // --help
    // Bad arguments exit 1 like every other bad input (CLI11's own codes are 104-108).
    std::cerr << "facetd: " << e.what() << " ('facetd --help' lists the options)\n";
    return 1;
  }
  spdlog::set_level(spdlog::level::from_str(logLevel));
  spdlog::set_pattern("%Y-%m-%dT%H:%M:%S.%e %^%l%$ facetd %v");
  if (printParts)
    spdlog::set_level(std::max(spdlog::level::warn, spdlog::level::from_str(logLevel)));

  // Signals are taken synchronously by the main thread; every other thread has them blocked.
  sigset_t signals;
  sigemptyset(&signals);
  for (int s : {SIGTERM, SIGINT, SIGHUP}) sigaddset(&signals, s);
  pthread_sigmask(SIG_BLOCK, &signals, nullptr);

  const service::SystemdNotifier systemd;
  const auto loaded = config::loadStationConfig(configFile);
  if (!loaded.station) {
    std::cerr << loaded.diagnostics.text();
    std::cerr << "facetd: " << configFile << ": station config has errors\n";
    return 1;
  }
  config::StationConfig stationConfig = *loaded.station;
  if (!replayFolder.empty()) useReplay(stationConfig, replayFolder);
  std::map<std::string, std::uint64_t> counts;
  std::uint64_t unexpected = 0;
  service::StationOptions options;
  options.recipe = recipe;
  options.maxParts = maxParts;
  options.stopAtEndOfStream = exitAtEnd || !replayFolder.empty();
  options.usePlc = !noPlc;
  // A replayed folder can wait for the inspection: nothing is dropped.
  options.overflow = blockWhenBehind || !replayFolder.empty() ? service::OverflowPolicy::Block
                                                              : service::OverflowPolicy::DropOldest;
  // Results to the fleet (the station file's mqtt / postgres sections): each part is handed over
  // after the PLC has it, and only appended to the sinks' outboxes here (never waits on a peer).
  std::unique_ptr<service::FleetPublishers> fleet;
  try {
    fleet = std::make_unique<service::FleetPublishers>(stationConfig);
  } catch (const std::exception& e) {
    std::cerr << "facetd: " << e.what() << "\n";
    return 1;
  }
  if (fleet->any()) options.onPart = [&](const service::PartResult& p) { fleet->submit(p); };
  if (printParts) {
    options.onPart = [&, toFleet = options.onPart](const service::PartResult& p) {
      if (toFleet) toFleet(p);
      ++counts[service::verdictName(p.verdict)];
      if (!p.expectedVerdict.empty() && p.expectedVerdict != service::verdictName(p.verdict))
        ++unexpected;
      std::cout << partLine(p) << std::endl;
    };
  }
  try {
    service::checkCalibrationImageSize(stationConfig);
    service::Station station(stationConfig, kinds, options);
    const auto& httpConfig = station.config().http;
    service::FleetStationView view(station, *fleet, station.metrics());
    service::HttpServer http(view, {.bindAddress = httpConfig.bind,
                                    .port = httpConfig.port,
                                    .token = httpConfig.token,
                                    .dashboardDir = {}});
    http.start();
    spdlog::info("http listening on {}:{}", httpConfig.bind, http.port());
    if (!portFile.empty()) std::ofstream(portFile) << http.port() << "\n";
    fleet->start();
    station.start();
    // READY once camera and PLC are up; a PLC still unreachable after a few seconds does not
    // hold the service back (parts are queued for it), the status says so.
    const auto readyDeadline = std::chrono::steady_clock::now() + 5s;
    while (!station.plcConnected() && std::chrono::steady_clock::now() < readyDeadline)
      std::this_thread::sleep_for(20ms);
    systemd.ready(station.plcConnected() ? "inspecting" : "inspecting; PLC not connected");
    if (options.usePlc && station.config().hasPlc && !station.plcConnected())
      spdlog::warn(
          "PLC at {}:{} not reachable: parts wait for it. Is the PLC on and reachable? For a demo "
          "start the simulator (facet plc-sim --map {} --key plc.register_map --port {}); to "
          "inspect without a PLC run facetd with --no-plc",
          station.config().plc.host, station.config().plc.port, configFile,
          station.config().plc.port);

    const timespec tick{0, 200'000'000};
    auto lastChangeCheck = std::chrono::steady_clock::now();
    while (!station.drained()) {
      const int sig = sigtimedwait(&signals, nullptr, &tick);
      if (sig == SIGHUP) {
        systemd.reloading();
        const auto report = station.reloadRecipes();
        spdlog::info("SIGHUP: recipes reloaded ({} changed, {} rejected)", report.loaded.size(),
                     report.rejected.size());
        systemd.ready("inspecting");
      } else if (sig == SIGTERM || sig == SIGINT) {
        spdlog::info("{}: finishing the parts in progress", sig == SIGTERM ? "SIGTERM" : "SIGINT");
        systemd.stopping();
        station.requestStop();
        break;
      }
      // A hung inspection or acquisition loop stops the pings, and systemd restarts us.
      if (station.loopsAlive(std::max<std::chrono::milliseconds>(
              5000ms,
              std::chrono::duration_cast<std::chrono::milliseconds>(systemd.watchdogInterval()))))
        systemd.watchdog();
      if (std::chrono::steady_clock::now() - lastChangeCheck > 1s) {
        lastChangeCheck = std::chrono::steady_clock::now();
        // Polled rather than inotify: cheap (sizes and times) and works on any filesystem.
        if (station.recipesChangedOnDisk()) {
          const auto report = station.reloadRecipes();
          spdlog::info("recipe files changed: {} reloaded, {} rejected", report.loaded.size(),
                       report.rejected.size());
        }
      }
    }
    station.requestStop();
    station.join();
    // What is still in the outboxes stays on disk for the next start; a short flush first.
    fleet->stop(std::chrono::milliseconds(2000));
    http.stop();
    if (printParts) {
      std::cout << "summary:";
      for (const auto& [verdict, n] : counts) std::cout << "  " << verdict << "=" << n;
      std::cout << "  unexpected=" << unexpected << "\n"
                << "results: " << station.config().results.database.string() << "\n";
      if (!station.config().archive.folder.empty())
        std::cout << "archive: " << station.config().archive.folder.string() << "\n";
    }
    return 0;
  } catch (const std::exception& e) {
    std::cerr << "facetd: " << e.what() << "\n";
    return 1;
  }
}
