#include "tests/daemon/line_run.hpp"

#include <sqlite3.h>

#include <filesystem>
#include <fstream>
#include <memory>
#include <stdexcept>
#include <thread>

#include "config/station_config.hpp"
#include "tests/plc/pymodbus_peer.hpp"

namespace facet::daemon_test {

namespace {

std::string text(sqlite3_stmt* s, int column) {
  const auto* p = sqlite3_column_text(s, column);
  return p ? reinterpret_cast<const char*>(p) : "";
}

// Runs `sql` on a read-only connection and calls `row` per result row. The connection and the
// statement are released even when `row` throws (callers poll while facetd is still writing).
template <typename Row>
void query(const std::string& database, const std::string& sql, Row row) {
  sqlite3* raw = nullptr;
  const int opened = sqlite3_open_v2(database.c_str(), &raw, SQLITE_OPEN_READONLY, nullptr);
  const std::unique_ptr<sqlite3, int (*)(sqlite3*)> db(raw, sqlite3_close);
  if (opened != SQLITE_OK) throw std::runtime_error(database + ": cannot open");
  sqlite3_busy_timeout(db.get(), 5000);  // facetd may be writing (WAL) or creating the schema
  sqlite3_stmt* rawStatement = nullptr;
  if (sqlite3_prepare_v2(db.get(), sql.c_str(), -1, &rawStatement, nullptr) != SQLITE_OK)
    throw std::runtime_error(database + ": " + sqlite3_errmsg(db.get()));
  const std::unique_ptr<sqlite3_stmt, int (*)(sqlite3_stmt*)> statement(rawStatement,
                                                                        sqlite3_finalize);
  while (sqlite3_step(statement.get()) == SQLITE_ROW) row(statement.get());
}

}  // namespace

std::map<std::string, ExpectedPart> expectedParts(const std::string& folder) {
  std::map<std::string, ExpectedPart> parts;
  for (const auto& entry : std::filesystem::directory_iterator(folder)) {
    const auto name = entry.path().filename().string();
    if (entry.path().extension() != ".json") continue;
    const auto j = nlohmann::json::parse(std::ifstream(entry.path()));
    const auto& a = j.contains("annotations") ? j.at("annotations") : j;
    parts[name.substr(0, name.size() - 5)] = {a.value("serial", ""),
                                              a.value("expected_verdict", "")};
  }
  return parts;
}

std::vector<StoredPart> storedParts(const std::string& database) {
  std::vector<StoredPart> parts;
  std::map<std::int64_t, std::size_t> index;
  query(database,
        "SELECT part_id, recipe_id, frame_id, source, serial, expected, verdict, failed_checks, "
        "error, recipe_name, recipe_version "
        "FROM parts ORDER BY part_id",
        [&](sqlite3_stmt* s) {
          StoredPart p;
          p.partId = sqlite3_column_int64(s, 0);
          p.recipeId = sqlite3_column_int(s, 1);
          p.frameId = sqlite3_column_int64(s, 2);
          p.source = text(s, 3);
          p.serial = text(s, 4);
          p.expected = text(s, 5);
          p.verdict = text(s, 6);
          p.failedChecks = text(s, 7);
          p.error = text(s, 8);
          p.recipeName = text(s, 9);
          p.recipeVersion = text(s, 10);
          index[p.partId] = parts.size();
          parts.push_back(p);
        });
  // Two connections, two snapshots: facetd may have stored more parts since the first query.
  // Their measurements are left out; an unknown part below that bound is a real orphan.
  const std::int64_t lastRead = parts.empty() ? 0 : parts.back().partId;
  query(database,
        "SELECT part_id, name, value, checked, pass FROM measurements WHERE part_id <= " +
            std::to_string(lastRead),
        [&](sqlite3_stmt* s) {
          auto it = index.find(sqlite3_column_int64(s, 0));
          if (it == index.end()) throw std::runtime_error("measurement of an unknown part");
          parts[it->second].measurements[text(s, 1)] = {sqlite3_column_double(s, 2),
                                                        sqlite3_column_int(s, 3) != 0,
                                                        sqlite3_column_int(s, 4) != 0};
        });
  return parts;
}

std::optional<std::vector<StoredPart>> waitForStored(
    const std::string& database, const std::function<bool(const std::vector<StoredPart>&)>& done,
    std::chrono::milliseconds timeout) {
  const auto until = std::chrono::steady_clock::now() + timeout;
  while (true) {
    std::vector<StoredPart> parts;
    try {
      if (std::filesystem::exists(database)) parts = storedParts(database);
    } catch (const std::exception&) {
      // facetd has created the file but not yet its tables
    }
    if (done(parts)) return parts;
    if (std::chrono::steady_clock::now() > until) return std::nullopt;
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
}

std::string integrityCheck(const std::string& database) {
  std::string answer;
  query(database, "PRAGMA integrity_check", [&](sqlite3_stmt* s) { answer += text(s, 0); });
  return answer;
}

std::string journalMode(const std::string& database) {
  std::string answer;
  query(database, "PRAGMA journal_mode", [&](sqlite3_stmt* s) { answer += text(s, 0); });
  return answer;
}

std::string writeStationFile(const std::string& dir, const std::string& camera, int plcPort,
                             const StationFileOptions& options) {
  const std::string recipes = std::string(FACET_SOURCE_DIR) + "/recipes";
  std::ofstream f(dir + "/station.yaml");
  f << "schema_version: 1\nname: integration-station\ncamera:\n" << camera;
  f << "  scans:\n    folder: " << recipes << "/demo/scan_offset\n    glob: \"*.csv\"\n";
  {  // always written (--no-plc ignores it); a station without one is covered by config tests
    f << "plc:\n  role: client\n  mode: " << options.plcMode
      << "\n  transport: tcp\n  host: 127.0.0.1\n"
      << "  port: " << (plcPort > 0 ? plcPort : 502) << "\n  unit_id: 1\n  word_order: ABCD\n"
      << "  response_timeout_ms: 500\n  heartbeat_period_ms: 1000\n"
      << options.plcExtra << "  register_map:\n    address_base: 0\n    control:\n"
      << "      trigger: {coil: 0}\n      result_ack: {coil: 1}\n"
      << "      recipe_select: {register: 0}\n    status:\n"
      << "      ready: {coil: 16}\n      busy: {coil: 17}\n      result_valid: {coil: 18}\n"
      << "      pass: {coil: 19}\n      completed_toggle: {coil: 20}\n"
      << "      missed_trigger: {coil: 21}\n      error: {coil: 22}\n"
      << "      error_code: {register: 10}\n      heartbeat: {register: 11}\n"
      << "      inspection_counter: {register: 12}\n      active_recipe: {register: 13}\n";
  }
  f << "recipes: " << (options.recipes.empty() ? recipes : options.recipes) << "\n";
  f << "results:\n  database: " << dir << "/results.db\n" << options.resultsExtra;
  f << "archive:\n  folder: " << dir << "/archive\n  quota_mb: " << options.archiveQuotaMb
    << "\n  keep: " << options.archiveKeep << "\n";
  f << "http:\n  bind: 127.0.0.1\n  port: 0\n";
  f << "calibration:\n"
    << (options.calibration.empty() ? "  file: " + recipes + "/calibration.yaml\n"
                                    : options.calibration);
  return dir + "/station.yaml";
}

std::string writePeerConfig(const std::string& stationFile, bool freeRun) {
  const auto loaded = config::loadStationConfig(stationFile);
  if (!loaded.station) throw std::runtime_error(loaded.diagnostics.text());
  plc::RegisterMap map = loaded.station->registerMap;
  // bracket_shape.recipe.yaml's outputs, as its checks declare them (word order: the station's).
  auto output = [](std::string name, int address, plc::ValueType type, double factor) {
    plc::ResultOutput o;
    o.name = std::move(name);
    o.address = address;
    o.type = type;
    o.factor = factor;
    o.wordOrder = plc::WordOrder::ABCD;
    return o;
  };
  map.results = {output("label.count", 110, plc::ValueType::Int16, 1.0),
                 output("bore_to_edge.distance", 111, plc::ValueType::Float32, 1.0),
                 output("label_angle.angle", 113, plc::ValueType::ScaledInt16, 100.0)};
  return freeRun ? plc::test::writePeerConfig(map, true, 512, 128, {{"report_writes", true}})
                 : plc::test::writePeerConfig(map, false);
}

}  // namespace facet::daemon_test
