// facetd end to end with its fleet sinks: a real mosquitto broker and a throw-away PostgreSQL
// cluster, both away when facetd starts, then started; facetd keeps inspecting, says "degraded",
// buffers, and delivers every part once in order when they are there. Its last will says
// "offline" when it dies.
#include <gtest/gtest.h>

#include <csignal>
#include <fstream>
#include <string>
#include <thread>

#include <nlohmann/json.hpp>

#include "tests/daemon/child_process.hpp"
#include "tests/daemon/facetd_http.hpp"
#include "tests/sinks/mosquitto_broker.hpp"
#include "tests/sinks/postgres_cluster.hpp"

namespace facet::sinks_test {
namespace {

using namespace std::chrono_literals;
const std::string kSource = FACET_SOURCE_DIR;

std::string writeStation(const daemon_test::TempDir& dir, int brokerPort,
                         const PostgresCluster& db) {
  std::ofstream f(dir / "station.yaml");
  f << "schema_version: 1\nname: cam1\ncamera:\n  backend: replay\n  replay:\n"
    << "    folder: " << kSource << "/recipes/demo/bracket_registration\n"
    << "    glob: \"*.png\"\n    loop: true\n    fps: 20\n    trigger: software\n"
    << "    colour: mono\nrecipes: " << kSource
    << "/recipes\nresults:\n  database: " << (dir / "results.db")
    << "\nhttp:\n  port: 0\ncalibration:\n  file: " << kSource << "/recipes/calibration.yaml\n"
    << "mqtt:\n  port: " << brokerPort << "\n  keepalive_s: 5\n  reconnect_max_ms: 500\n"
    << "  outbox: " << (dir / "mqtt-outbox") << "\n"
    << "postgres:\n  connection: \"" << db.connection()
    << "\"\n  password: " << PostgresCluster::kPassword
    << "\n  reconnect_max_ms: 500\n  outbox: " << (dir / "pg-outbox") << "\n";
  return dir / "station.yaml";
}

std::vector<std::uint64_t> resultIds(const std::vector<MqttMessage>& messages) {
  std::vector<std::uint64_t> ids;
  for (const auto& m : messages)
    if (m.topic == "facet/cam1/result")
      ids.push_back(nlohmann::json::parse(m.payload).at("part_id").get<std::uint64_t>());
  return ids;
}

TEST(FacetdFleet, PeersAwayAtStartThenBackEveryPartOnceInOrderAndAWillWhenKilled) {
  daemon_test::TempDir dir;
  MosquittoBroker broker(dir.path());
  PostgresCluster db(dir.path());
  db.kill();
  // The line's subscriber has a persistent session at the broker from before the outage.
  broker.start();
  {
    MqttSubscriber early("line-mes", broker.port(), "facet/cam1/#");
    ASSERT_TRUE(early.waitSubscribed(10s));
  }
  broker.stop();
  const auto station = writeStation(dir, broker.port(), db);
  daemon_test::ChildProcess facetd({FACETD_PATH, "--config", station, "--no-plc",
                                    "--http-port-file", dir / "port", "--log-level", "info"},
                                   {}, dir / "facetd.log");
  const auto port = daemon_test::waitForHttpPort(dir / "port", 30s);
  ASSERT_TRUE(port) << facetd.outputTail();

  // Both peers away: facetd runs, says degraded and why, and buffers.
  nlohmann::json health;
  for (int i = 0; i < 100; ++i) {
    health = daemon_test::healthz(*port);
    if (health.contains("mqtt") && health["mqtt"]["buffered"].get<int>() >= 5 &&
        health["postgres"]["buffered"].get<int>() >= 5 &&
        health["postgres"]["last_error"].get<std::string>().starts_with("cannot connect"))
      break;
    std::this_thread::sleep_for(100ms);
  }
  EXPECT_EQ(health["status"], "degraded") << health.dump();
  EXPECT_FALSE(health["mqtt"]["connected"].get<bool>());
  EXPECT_NE(health["mqtt"]["last_error"].get<std::string>().find("refused"), std::string::npos)
      << health.dump();
  EXPECT_GE(health["postgres"]["buffered"].get<int>(), 5) << health.dump();
  const auto metrics = daemon_test::httpGet(*port, "/metrics");
  ASSERT_TRUE(metrics);
  EXPECT_EQ(daemon_test::metricValue(*metrics, "facet_sink_connected{sink=\"mqtt\"}"), 0.0);

  // The peers come back.
  broker.start();
  MqttSubscriber subscriber("line-mes", broker.port(), "facet/cam1/#");
  ASSERT_TRUE(subscriber.waitSubscribed(10s));
  db.start();
  for (int i = 0; i < 200; ++i) {
    health = daemon_test::healthz(*port);
    if (health["status"] == "ok") break;
    std::this_thread::sleep_for(100ms);
  }
  EXPECT_EQ(health["status"], "ok") << health.dump();
  std::this_thread::sleep_for(1s);  // a few parts more while both are up

  facetd.signal(SIGTERM);
  ASSERT_EQ(facetd.wait(30s), 0) << facetd.outputTail();
  const auto stored = db.query("SELECT count(*) FROM parts");
  ASSERT_TRUE(subscriber.waitFor(
      [&](const auto& m) { return resultIds(m).size() >= std::stoul(stored); }, 20s))
      << resultIds(subscriber.messages()).size() << " of " << stored;
  std::this_thread::sleep_for(300ms);  // a repeated message would arrive now
  const auto ids = resultIds(subscriber.messages());
  // Every part facetd made, once each, in order, over MQTT and in PostgreSQL.
  ASSERT_EQ(std::to_string(ids.size()), stored);
  for (std::size_t i = 0; i < ids.size(); ++i) ASSERT_EQ(ids[i], i + 1);
  EXPECT_EQ(db.query("SELECT min(part_id) FROM parts"), "1");
  EXPECT_EQ(db.query("SELECT count(DISTINCT part_id) FROM parts"), stored);
  EXPECT_EQ(db.query("SELECT max(part_id) FROM parts"), stored);
  const auto messages = subscriber.messages();
  EXPECT_EQ(messages.back().topic, "facet/cam1/status");
  EXPECT_EQ(messages.back().payload, "offline");  // a clean stop says so itself

  // Killed: the broker publishes the will (after 1.5 keep-alives, 7.5 s).
  auto statusAfter = [](std::size_t from, const std::string& payload) {
    return [from, payload](const std::vector<MqttMessage>& m) {
      for (std::size_t i = from; i < m.size(); ++i)
        if (m[i].topic == "facet/cam1/status" && m[i].payload == payload) return true;
      return false;
    };
  };
  const std::size_t before = subscriber.messages().size();
  daemon_test::ChildProcess again({FACETD_PATH, "--config", station, "--no-plc"}, {},
                                  dir / "facetd2.log");
  ASSERT_TRUE(subscriber.waitFor(statusAfter(before, "online"), 30s));
  const std::size_t online = subscriber.messages().size();
  again.signal(SIGKILL);
  again.wait(5s);
  EXPECT_TRUE(subscriber.waitFor(statusAfter(online, "offline"), 20s));
}

}  // namespace
}  // namespace facet::sinks_test
