#pragma once
// LineRun: one facetd on a production line made of real peers, as the integration tests see it:
// the station file the test generated, the pymodbus PLC (tests/plc/pymodbus_plc.py) raising
// triggers, and, afterwards, what facetd left in its SQLite results store.

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

// Every row of the results store, in part order.
std::vector<StoredPart> storedParts(const std::string& database);
// PRAGMA integrity_check's answer ("ok" when the file is sound).
std::string integrityCheck(const std::string& database);

// The station file for a test: results, archive and HTTP in `dir`; `camera` is the YAML of the
// camera section (indented by two spaces); plcPort 0: a placeholder PLC section for facetd
// --no-plc.
std::string writeStationFile(const std::string& dir, const std::string& camera, int plcPort);

// The pymodbus peer's config for that station and the bracket_shape recipe's PLC outputs.
std::string writePeerConfig(const std::string& stationFile);

}  // namespace facet::daemon_test
