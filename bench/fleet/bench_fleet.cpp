// bench_fleet: what results to the fleet cost, and how fast archived images are re-inspected.
//
//   sinks       PLC trigger raised -> result registers read by the PLC (plc::PlcSimulator, a
//               Modbus TCP server in this process), one part at a time, facetd's pipeline in
//               process (service::Station) on the example station's recorded bracket images:
//               without sinks (the baseline), with the MQTT and PostgreSQL sinks delivering to
//               a real mosquitto broker and a throw-away PostgreSQL cluster started here, and with
//               both peers down (results buffering on disk). The three runs alternate in blocks
//               within one run. Each part goes to the sinks the way facetd hands it over: after
//               the PLC, on the publishing thread (FleetPublishers::submit).
//   outages     each peers-down block is an outage: the parts it buffered, then the peers are
//               started again under the same station and the parts they take (MQTT PUBACKs,
//               rows the database gained) and how long the backlog took to drain.
//   replay      images per CPU-second (one core) of `facet replay --results` (batch path:
//               service/batch) over the example recipes' recorded folders, beside the HTML-report
//               replay (`facet replay --report`: the replay camera and the same inspection) as
//               baseline, and images per second of N shard threads at once.
//
//   bench_fleet [--smoke] [--triggers N] [--rounds N]
#include <time.h>

#include <algorithm>
#include <chrono>
#include <condition_variable>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include <spdlog/spdlog.h>

#include "bench/machine_state.hpp"
#include "camera/camera_factory.hpp"
#include "config/recipe_loader.hpp"
#include "config/station_config.hpp"
#include "plc/plc_simulator.hpp"
#include "service/batch/batch_replay.hpp"
#include "service/daemon/part_origin.hpp"
#include "service/daemon/station.hpp"
#include "service/engine/builtin_steps.hpp"
#include "service/engine/inspect_part.hpp"
#include "service/sinks/fleet_publishers.hpp"
#include "tests/sinks/mosquitto_broker.hpp"
#include "tests/sinks/postgres_cluster.hpp"

namespace {

using namespace facet;
using namespace std::chrono_literals;
using Clock = std::chrono::steady_clock;
namespace fs = std::filesystem;

const fs::path kSource = FACET_SOURCE_DIR;

double percentile(std::vector<double> v, double q) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  const auto i = static_cast<std::size_t>(q * static_cast<double>(v.size()));
  return v[std::min(i, v.size() - 1)];
}

using bench::cpuSeconds;
using bench::loadAverage;

// The example station, its camera replaying the recorded bracket parts in a loop, its PLC the
// simulator on `plcPort`, its stores in `dir`.
config::StationConfig exampleStation(const fs::path& dir, int plcPort) {
  fs::create_directories(dir);
  std::ifstream in(kSource / "recipes/station.yaml");
  std::string text((std::istreambuf_iterator<char>(in)), {});
  auto replace = [&](const std::string& from, const std::string& to) {
    const auto at = text.find(from);
    if (at == std::string::npos) throw std::runtime_error("station.yaml changed: " + from);
    text.replace(at, from.size(), to);
  };
  replace("port: 1502", "port: " + std::to_string(plcPort));
  replace("/tmp/facet-demo-results.db", (dir / "results.db").string());
  replace("/tmp/facet-demo-archive", (dir / "archive").string());
  replace("port: 8080", "port: 0");
  replace("fps: 5", "fps: 0");
  const fs::path file =
      kSource / "recipes" / ("bench-fleet-" + std::to_string(::getpid()) + ".yaml");
  std::ofstream(file) << text;
  auto loaded = config::loadStationConfig(file);
  fs::remove(file);
  if (!loaded.station) throw std::runtime_error(loaded.diagnostics.text());
  return *loaded.station;
}

enum class Sinks { None, Delivering, PeersDown };
const char* name(Sinks s) {
  return s == Sinks::None         ? "no sinks (baseline)"
         : s == Sinks::Delivering ? "MQTT + PostgreSQL, peers up"
                                  : "MQTT + PostgreSQL, peers down";
}

struct Peers {
  sinks_test::MosquittoBroker* broker;
  sinks_test::PostgresCluster* db;
};

// One outage: what the sinks buffered while the peers were down, and what reached them after.
struct Outage {
  std::uint64_t parts = 0;  // parts inspected during the outage (warm-up included)
  std::uint64_t bufferedMqtt = 0, bufferedPostgres = 0;
  std::uint64_t deliveredMqtt = 0, deliveredPostgres = 0;  // after the peers came back
  std::uint64_t rowsGained = 0;                            // parts table, counted by SQL
  std::uint64_t dropped = 0;
  double drainS = 0;  // peers up -> both outboxes empty
};

std::uint64_t partRows(const Peers& peers) {
  return std::stoull(peers.db->query("SELECT count(*) FROM parts"));
}

// The peers are down: counts the backlog, starts them, waits until the backlog is delivered.
Outage recover(const service::FleetPublishers& fleet, const Peers& peers, std::uint64_t parts) {
  Outage o;
  o.parts = parts;
  auto health = fleet.health();
  o.bufferedMqtt = health["mqtt"]["buffered"].get<std::uint64_t>();
  o.bufferedPostgres = health["postgres"]["buffered"].get<std::uint64_t>();
  peers.broker->start();
  peers.db->start();
  const auto rowsBefore = partRows(peers);
  const auto t0 = Clock::now();
  while (Clock::now() - t0 < 120s) {
    health = fleet.health();
    if (health["mqtt"]["buffered"] == 0 && health["postgres"]["buffered"] == 0) break;
    std::this_thread::sleep_for(5ms);
  }
  o.drainS = std::chrono::duration<double>(Clock::now() - t0).count();
  o.deliveredMqtt = health["mqtt"]["delivered"].get<std::uint64_t>();
  o.deliveredPostgres = health["postgres"]["delivered"].get<std::uint64_t>();
  o.dropped = health["mqtt"]["dropped"].get<std::uint64_t>() +
              health["postgres"]["dropped"].get<std::uint64_t>();
  o.rowsGained = partRows(peers) - rowsBefore;
  return o;
}

// `triggers` parts, one at a time; returns trigger -> result registers in ms. With the peers
// down, `outage` gets the backlog and its recovery (the peers are up again afterwards).
std::vector<double> latencyRun(const fs::path& dir, Sinks sinks, const Peers& peers, int triggers,
                               std::uint64_t* delivered, Outage* outage = nullptr) {
  auto probe = exampleStation(dir / "probe", 1);
  plc::PlcSimulator plc(probe.registerMap, {});
  std::mutex mutex;
  std::condition_variable arrived;
  std::vector<Clock::time_point> received;
  plc.onResult([&](const plc::ReceivedResult& r) {
    std::lock_guard lock(mutex);
    received.push_back(r.receivedAt);
    arrived.notify_all();
  });
  plc.start();
  auto station = exampleStation(dir / "station", plc.port());
  if (sinks != Sinks::None) {
    station.mqtt.enabled = true;
    station.mqtt.port = peers.broker->port();
    station.mqtt.clientId = "bench-fleet";
    station.mqtt.outbox.folder = dir / "mqtt-outbox";
    station.postgres.enabled = true;
    station.postgres.connection = peers.db->connection();
    station.postgres.password = sinks_test::PostgresCluster::kPassword;
    station.postgres.outbox.folder = dir / "pg-outbox";
  }
  service::FleetPublishers fleet(station);
  fleet.start();
  service::StationOptions options;
  std::uint64_t parts = 0;
  options.onPart = [&](const service::PartResult& p) {
    fleet.submit(p);
    ++parts;
  };
  std::vector<double> ms;
  const auto kinds = service::builtinSteps();  // the station keeps a reference
  {
    service::Station s(station, kinds, options);
    s.start();
    for (int i = -5; i < triggers; ++i) {  // 5 warm-up parts while the PLC link connects
      std::unique_lock lock(mutex);
      const std::size_t before = received.size();
      const auto t0 = Clock::now();
      lock.unlock();
      plc.raiseTrigger();
      lock.lock();
      if (!arrived.wait_for(lock, 5s, [&] { return received.size() > before; })) {
        if (i < 0) continue;
        throw std::runtime_error("no result within 5 s of a trigger");
      }
      if (i >= 0)
        ms.push_back(std::chrono::duration<double, std::milli>(received.back() - t0).count());
      lock.unlock();
      std::this_thread::sleep_for(10ms);
    }
    s.requestStop();
    s.join();
  }
  if (outage) *outage = recover(fleet, peers, parts);
  fleet.stop(sinks == Sinks::None ? 0ms : 5000ms);
  const auto health = fleet.health();
  if (delivered && health.contains("mqtt"))
    *delivered = health["mqtt"]["delivered"].get<std::uint64_t>() +
                 health["postgres"]["delivered"].get<std::uint64_t>();
  plc.stop();
  return ms;
}

struct ReplayRate {
  std::string recipe;
  int images = 0;
  double batchPerCpuS = 0, reportPerCpuS = 0, shardsPerS = 0;
};

// One recipe over its recorded folder: the batch path, the report path's camera loop, and
// `shards` threads each taking its shard.
ReplayRate replayRate(const std::string& recipeName, int passes, int shards) {
  const auto station = config::loadStationConfig(kSource / "recipes/station.yaml").station;
  const auto kinds = service::builtinSteps();
  const auto loaded = config::loadRecipe(kSource / "recipes" / (recipeName + ".recipe.yaml"), kinds,
                                         station->recipeLoadOptions());
  if (!loaded.recipe) throw std::runtime_error(loaded.diagnostics.text());
  auto recipe = std::make_shared<const config::Recipe>(*loaded.recipe);
  const auto prepared = service::prepareRecipe(recipe, station->calibration);
  const bool scans = service::scanRecipe(*prepared);
  const fs::path folder = kSource / "recipes/demo" / recipeName;
  const auto sidecars = SidecarMetadata::loadFolder(folder);
  ReplayRate r{recipeName};

  const auto all = service::listShare(folder, "", scans, {});
  double cpu0 = cpuSeconds(CLOCK_PROCESS_CPUTIME_ID);
  for (int p = 0; p < passes; ++p)
    for (const auto& part : all)
      (void)service::inspectRecordedPart(*prepared, part, sidecars, scans);
  r.images = static_cast<int>(all.size()) * passes;
  r.batchPerCpuS = r.images / (cpuSeconds(CLOCK_PROCESS_CPUTIME_ID) - cpu0);

  if (!scans) {
    // The report path's loop (service/cli/replay_command.cpp): the replay camera reads (and
    // prefetches) the files, the same inspection runs on each.
    CameraSettings settings;
    settings.backend = CameraBackend::Replay;
    settings.replay.folder = folder;
    settings.replay.loop = false;
    cpu0 = cpuSeconds(CLOCK_PROCESS_CPUTIME_ID);
    int n = 0;
    for (int p = 0; p < passes; ++p) {
      auto camera = makeCamera(settings);
      camera->open();
      camera->start();
      while (true) {
        auto grab = camera->grab(5000ms);
        if (grab.status == GrabStatus::EndOfStream || !grab.ok()) break;
        service::PartResult part;
        service::recordPartOrigin(part, recipe.get(), grab.frame);
        service::recordOutcome(
            part, service::inspectPart({.image = grab.frame.image, .scan = {}}, *prepared));
        ++n;
      }
      camera->stop();
      camera->close();
    }
    r.reportPerCpuS = n / (cpuSeconds(CLOCK_PROCESS_CPUTIME_ID) - cpu0);
  }

  const auto t0 = Clock::now();
  std::vector<std::thread> threads;
  for (int s = 0; s < shards; ++s)
    threads.emplace_back([&, s] {
      const auto share = service::listShare(folder, "", scans, {s, shards});
      for (int p = 0; p < passes; ++p)
        for (const auto& part : share)
          (void)service::inspectRecordedPart(*prepared, part, sidecars, scans);
    });
  for (auto& t : threads) t.join();
  r.shardsPerS = r.images / std::chrono::duration<double>(Clock::now() - t0).count();
  return r;
}

}  // namespace

int main(int argc, char** argv) {
  bool smoke = false;
  int triggers = 200, rounds = 3;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--smoke") smoke = true;
    if (a == "--triggers" && i + 1 < argc) triggers = std::stoi(argv[++i]);
    if (a == "--rounds" && i + 1 < argc) rounds = std::stoi(argv[++i]);
  }
  if (smoke) triggers = 20, rounds = 1;
  spdlog::set_level(spdlog::level::err);
  const fs::path dir = fs::temp_directory_path() / ("bench_fleet_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const unsigned cores = std::thread::hardware_concurrency();
  std::printf(
      "bench_fleet%s: %u cores, load average at start %s (a shared machine: absolute "
      "times vary with the load; compare rows of one run)\n\n",
      smoke ? " --smoke" : "", cores, loadAverage().c_str());
  try {
    sinks_test::MosquittoBroker broker(dir.string());
    broker.start();
    sinks_test::PostgresCluster db(dir.string());
    const Peers peers{&broker, &db};

    std::map<Sinks, std::vector<double>> latency;
    std::vector<Outage> outages;
    std::uint64_t delivered = 0;
    int block = 0;
    for (int round = 0; round < rounds; ++round)
      for (Sinks s : {Sinks::None, Sinks::Delivering, Sinks::PeersDown}) {
        if (s == Sinks::PeersDown) broker.kill(), db.kill();
        std::uint64_t d = 0;
        Outage outage;
        const auto ms = latencyRun(dir / ("run" + std::to_string(block++)), s, peers, triggers, &d,
                                   s == Sinks::PeersDown ? &outage : nullptr);
        latency[s].insert(latency[s].end(), ms.begin(), ms.end());
        if (s == Sinks::Delivering) delivered += d;
        if (s == Sinks::PeersDown) outages.push_back(outage);
      }
    std::printf(
        "PLC path: trigger raised -> result registers read, one part at a time, %d parts "
        "per row in %d alternating blocks\n\n",
        rounds * triggers, rounds);
    std::printf("| sinks                          |  p50 ms |  p99 ms | p50 ratio | p99 ratio |\n");
    std::printf("|--------------------------------|---------|---------|-----------|-----------|\n");
    const double base50 = percentile(latency[Sinks::None], 0.5);
    const double base99 = percentile(latency[Sinks::None], 0.99);
    for (Sinks s : {Sinks::None, Sinks::Delivering, Sinks::PeersDown}) {
      const double p50 = percentile(latency[s], 0.5), p99 = percentile(latency[s], 0.99);
      std::printf("| %-30s | %7.2f | %7.2f | %9.2f | %9.2f |\n", name(s), p50, p99, p50 / base50,
                  p99 / base99);
    }
    std::printf(
        "\nresults confirmed by broker + database in the peers-up runs: %llu of %d "
        "(MQTT and PostgreSQL each count a part; warm-up parts included)\n\n",
        static_cast<unsigned long long>(delivered), 2 * rounds * (triggers + 5));
    std::printf(
        "Outages: broker and database killed (SIGKILL) for one block, then started again; the "
        "same station's sinks deliver the backlog\n\n");
    std::printf(
        "| outage | parts | buffered MQTT | buffered PG | delivered MQTT | delivered PG | "
        "rows gained | dropped | drain s |\n");
    std::printf(
        "|--------|-------|---------------|-------------|----------------|--------------|"
        "-------------|---------|---------|\n");
    for (std::size_t i = 0; i < outages.size(); ++i) {
      const auto& o = outages[i];
      std::printf("| %6zu | %5llu | %13llu | %11llu | %14llu | %12llu | %11llu | %7llu | %7.2f |\n",
                  i + 1, static_cast<unsigned long long>(o.parts),
                  static_cast<unsigned long long>(o.bufferedMqtt),
                  static_cast<unsigned long long>(o.bufferedPostgres),
                  static_cast<unsigned long long>(o.deliveredMqtt),
                  static_cast<unsigned long long>(o.deliveredPostgres),
                  static_cast<unsigned long long>(o.rowsGained),
                  static_cast<unsigned long long>(o.dropped), o.drainS);
    }
    std::printf("\n");
  } catch (const std::exception& e) {
    std::printf("sinks: FAILED: %s\n", e.what());
    fs::remove_all(dir);
    return 1;
  }

  const int shards = static_cast<int>(std::max(2u, cores));
  std::printf(
      "Re-inspection of the recorded folders (images per CPU-second = per core; %d shard "
      "threads at once for the last column)\n\n",
      shards);
  std::printf(
      "| recipe                | images | batch img/cpu-s | report-path img/cpu-s "
      "(baseline) | ratio | %d shards img/s |\n",
      shards);
  std::printf(
      "|-----------------------|--------|-----------------|------------------------------"
      "-|-------|----------------|\n");
  for (const char* recipe :
       {"bracket_registration", "bracket_shape", "fiducial_board", "scan_offset"}) {
    const auto r = replayRate(recipe, smoke ? 1 : 5, shards);
    if (r.reportPerCpuS > 0)
      std::printf("| %-21s | %6d | %15.1f | %29.1f | %5.2f | %14.1f |\n", r.recipe.c_str(),
                  r.images, r.batchPerCpuS, r.reportPerCpuS, r.batchPerCpuS / r.reportPerCpuS,
                  r.shardsPerS);
    else
      std::printf("| %-21s | %6d | %15.1f | %29s | %5s | %14.1f |\n", r.recipe.c_str(), r.images,
                  r.batchPerCpuS, "(scans: no camera path)", "-", r.shardsPerS);
  }
  std::printf("\nload average at the end %s\n", loadAverage().c_str());
  fs::remove_all(dir);
  return 0;
}
