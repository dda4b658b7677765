// The station file's mqtt and postgres sections: read into their settings, every problem
// reported with its line and column.
#include <gtest/gtest.h>

#include "config/station_config.hpp"
#include "tests/config/config_test_support.hpp"

namespace facet::config::test {
namespace {

// Lines 1-11: a minimal station; sections appended from line 12 on.
const std::string kStation = R"(schema_version: 1
name: line3-cam1
camera:
  backend: replay
  replay:
    folder: .
recipes: .
results:
  database: results.db
calibration:
  mm_per_pixel: 0.05
)";

class FleetSections : public testing::Test {
 protected:
  StationLoadResult load(const std::string& sections) {
    return loadStationConfig(scratch.write("station.yaml", kStation + sections));
  }
  ScratchFolder scratch;
};

TEST_F(FleetSections, AreReadWithTheirDefaults) {
  const auto r = load(R"(mqtt:
  host: broker.example
  username: cam1
  password: secret
postgres:
  connection: "host=db port=5433 dbname=facet user=cam1"
  password: pw
  batch_parts: 20
)");
  ASSERT_TRUE(r.station.has_value()) << r.diagnostics.text();
  const auto& m = r.station->mqtt;
  EXPECT_TRUE(m.enabled);
  EXPECT_EQ(m.host, "broker.example");
  EXPECT_EQ(m.port, 1883);
  EXPECT_EQ(m.clientId, "facet-line3-cam1");
  EXPECT_EQ(m.topicPrefix, "facet");
  EXPECT_EQ(m.username, "cam1");
  EXPECT_EQ(m.outbox.folder, scratch.path() / "mqtt-outbox");
  EXPECT_DOUBLE_EQ(m.outbox.quotaMb, 64.0);
  const auto& p = r.station->postgres;
  EXPECT_TRUE(p.enabled);
  EXPECT_EQ(p.connection, "host=db port=5433 dbname=facet user=cam1");
  EXPECT_EQ(p.password, "pw");
  EXPECT_EQ(p.batchParts, 20);
  EXPECT_EQ(p.outbox.folder, scratch.path() / "postgres-outbox");

  const auto none = load("");
  ASSERT_TRUE(none.station.has_value());
  EXPECT_FALSE(none.station->mqtt.enabled);
  EXPECT_FALSE(none.station->postgres.enabled);
}

TEST_F(FleetSections, TlsChangesTheDefaultPortAndNeedsItsFiles) {
  scratch.write("ca.pem", "not checked here");
  const auto r = load("mqtt:\n  tls:\n    ca_file: ca.pem\n");
  ASSERT_TRUE(r.station.has_value()) << r.diagnostics.text();
  EXPECT_EQ(r.station->mqtt.port, 8883);
  EXPECT_EQ(r.station->mqtt.caFile, scratch.path() / "ca.pem");
  const auto missing = load("mqtt:\n  tls:\n    ca_file: none.pem\n    cert_file: ca.pem\n");
  EXPECT_FALSE(missing.station.has_value());
  EXPECT_TRUE(
      hasDiagnostic(missing.diagnostics, 14, 14, "'ca_file' file 'none.pem' does not exist"))
      << missing.diagnostics.text();
  EXPECT_TRUE(hasDiagnostic(missing.diagnostics, 14, 5, "both 'cert_file' and 'key_file'"))
      << missing.diagnostics.text();
}

TEST_F(FleetSections, ProblemsAreReportedWithLineAndColumn) {
  const auto r = load(R"(mqtt:
  hots: broker
  port: 70000
  password: secret
  topic_prefix: "plant/+/x"
postgres:
  connection: "host=db dbnme=facet"
  outbox_quota_mb: 0
)");
  EXPECT_FALSE(r.station.has_value());
  const auto& d = r.diagnostics;
  EXPECT_TRUE(hasDiagnostic(d, 13, 3, "unknown key 'hots'")) << d.text();
  EXPECT_TRUE(hasDiagnostic(d, 14, 9, "70000")) << d.text();
  EXPECT_TRUE(hasDiagnostic(d, 15, 13, "'password' needs a 'username'")) << d.text();
  EXPECT_TRUE(hasDiagnostic(d, 16, 17, "'topic_prefix'")) << d.text();
  EXPECT_TRUE(hasDiagnostic(d, 18, 15, "dbnme")) << d.text();
  EXPECT_TRUE(hasDiagnostic(d, 19, 20, "outbox_quota_mb")) << d.text();
}

TEST_F(FleetSections, AStationNameThatCannotBeATopicIsRefused) {
  std::string text = kStation;
  text.replace(text.find("line3-cam1"), 10, "line3/cam1");
  const auto r = loadStationConfig(scratch.write("station.yaml", text + "mqtt: {}\n"));
  EXPECT_FALSE(r.station.has_value());
  EXPECT_TRUE(hasDiagnostic(r.diagnostics, 12, 7, "cannot be an MQTT topic level"))
      << r.diagnostics.text();
}

}  // namespace
}  // namespace facet::config::test
