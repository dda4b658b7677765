#pragma once
// LineRun: one facetd on a production line made of real peers, as the integration tests see it:
// the station file the test generated, the pymodbus PLC (tests/plc/pymodbus_plc.py) raising
// triggers, and, afterwards, what facetd left in its SQLite results store.

#include <chrono>
#include <functional>
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
  std::string recipeName, recipeVersion;  // recipe_version: the recipe file's content hash
  std::map<std::string, StoredMeasurement> measurements;
};

// Every row of the results store, in part order.
std::vector<StoredPart> storedParts(const std::string& database);
// Polls the store (every 100 ms) until `done` holds for its rows; returns them then, or nullopt
// when `timeout` passes first. A store facetd has not created yet counts as no rows.
std::optional<std::vector<StoredPart>> waitForStored(
    const std::string& database, const std::function<bool(const std::vector<StoredPart>&)>& done,
    std::chrono::milliseconds timeout);
// PRAGMA integrity_check's answer ("ok" when the file is sound).
std::string integrityCheck(const std::string& database);
// PRAGMA journal_mode as stored in the file ("wal" for facetd's store).
std::string journalMode(const std::string& database);

// What a test may change in the station file; the defaults are the repository's recipes folder
// and an archive of failed parts.
struct StationFileOptions {
  std::string recipes;                // recipes folder; empty: FACET_SOURCE_DIR/recipes
  std::string archiveKeep = "fail";   // archive.keep: none, fail or all
  double archiveQuotaMb = 50;         // archive.quota_mb
  std::string plcMode = "triggered";  // plc.mode: triggered or free_run
  std::string plcExtra;               // more keys of the plc section, YAML lines indented by two
                                      // spaces (e.g. "  queue_capacity: 16\n")
  std::string resultsExtra;           // more keys of the results section (e.g. "  keep_parts: 5\n")
  // The calibration section's keys (indented by two spaces); empty: the example station's file,
  // made for 640x480 frames (facetd refuses other frame sizes with it).
  std::string calibration;
};

// The station file for a test: results, archive and HTTP in `dir`; `camera` is the YAML of the
// camera section (indented by two spaces); plcPort 0: a placeholder PLC section for facetd
// --no-plc.
std::string writeStationFile(const std::string& dir, const std::string& camera, int plcPort,
                             const StationFileOptions& options = {});

// The pymodbus peer's config for that station and the bracket_shape recipe's PLC outputs. In
// free run the peer reports every write of the inspection counter (report_writes).
std::string writePeerConfig(const std::string& stationFile, bool freeRun = false);

}  // namespace facet::daemon_test
