#pragma once
// LineRun: one facetd on a production line made of real peers, as the integration tests see it:
// the station file the test generated, the pymodbus PLC (tests/plc/pymodbus_plc.py) raising
// triggers, and, afterwards, what facetd left in its SQLite results store.

#include <chrono>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace facet::daemon_test {

// What a recorded demo image is expected to give: from its sidecar, where the scene generator
// writes serial and expected_verdict either at the top level or under "annotations".
struct ExpectedPart {
  std::string serial;
  std::string verdict;  // pass, fail or error
};
std::map<std::string, ExpectedPart> expectedParts(const std::string& folder);

struct StoredMeasurement {
  double value = 0;
  bool checked = false;
  bool pass = true;
};

struct StoredPart {
  std::int64_t partId = 0;
  int recipeId = 0;
  std::int64_t frameId = 0;
  std::string source, serial, expected, verdict, failedChecks, error;
  std::map<std::string, StoredMeasurement> measurements;
};

// The body of GET http://127.0.0.1:<port><path>; throws std::runtime_error when facetd does not
// answer 200.
std::string httpGet(int port, const std::string& path);
// The value of one sample of a Prometheus exposition (`series` with its labels, e.g.
// facet_queue_depth{queue="plc"}); nullopt when absent.
std::optional<double> metricValue(const std::string& exposition, const std::string& series);
// The HTTP port facetd wrote to --http-port-file, waiting for it at most `timeout`; 0 if none.
int readHttpPort(const std::string& portFile, std::chrono::milliseconds timeout);

// Every row of the results store, in part order.
std::vector<StoredPart> storedParts(const std::string& database);
// PRAGMA integrity_check's answer ("ok" when the file is sound).
std::string integrityCheck(const std::string& database);
// PRAGMA journal_mode as stored in the file ("wal" for facetd's store).
std::string journalMode(const std::string& database);

// The station file for a test: results, archive and HTTP in `dir`; `camera` is the YAML of the
// camera section (indented by two spaces); plcPort 0: a placeholder PLC section for facetd
// --no-plc. `plcMode`: triggered or free_run; `plcOptions`: more keys of the plc section
// (YAML lines indented by two spaces, e.g. "  queue_capacity: 16\n").
std::string writeStationFile(const std::string& dir, const std::string& camera, int plcPort,
                             const std::string& plcMode = "triggered",
                             const std::string& plcOptions = "");

// The pymodbus peer's config for that station and the bracket_shape recipe's PLC outputs. In
// free run the peer reports every write of the inspection counter (report_writes).
std::string writePeerConfig(const std::string& stationFile, bool freeRun = false);

}  // namespace facet::daemon_test
