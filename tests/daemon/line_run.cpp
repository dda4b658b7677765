#include "tests/daemon/line_run.hpp"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <sqlite3.h>
#include <sys/socket.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>
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

// Runs `sql` on a read-only connection and calls `row` per result row.
template <typename Row>
void query(const std::string& database, const std::string& sql, Row row) {
  sqlite3* db = nullptr;
  if (sqlite3_open_v2(database.c_str(), &db, SQLITE_OPEN_READONLY, nullptr) != SQLITE_OK) {
    sqlite3_close(db);
    throw std::runtime_error(database + ": cannot open");
  }
  sqlite3_busy_timeout(db, 5000);  // facetd may be writing (WAL) or creating the schema
  sqlite3_stmt* s = nullptr;
  if (sqlite3_prepare_v2(db, sql.c_str(), -1, &s, nullptr) != SQLITE_OK) {
    const std::string message = sqlite3_errmsg(db);
    sqlite3_close(db);
    throw std::runtime_error(database + ": " + message);
  }
  while (sqlite3_step(s) == SQLITE_ROW) row(s);
  sqlite3_finalize(s);
  sqlite3_close(db);
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
        "error "
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
          index[p.partId] = parts.size();
          parts.push_back(p);
        });
  query(database, "SELECT part_id, name, value, checked, pass FROM measurements",
        [&](sqlite3_stmt* s) {
          auto it = index.find(sqlite3_column_int64(s, 0));
          if (it == index.end()) throw std::runtime_error("measurement of an unknown part");
          parts[it->second].measurements[text(s, 1)] = {sqlite3_column_double(s, 2),
                                                        sqlite3_column_int(s, 3) != 0,
                                                        sqlite3_column_int(s, 4) != 0};
        });
  return parts;
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

std::string httpGet(int port, const std::string& path) {
  const int fd = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  address.sin_port = htons(static_cast<std::uint16_t>(port));
  if (fd < 0 || ::connect(fd, reinterpret_cast<sockaddr*>(&address), sizeof(address)) != 0) {
    if (fd >= 0) ::close(fd);
    throw std::runtime_error("facetd does not answer on port " + std::to_string(port));
  }
  const std::string request =
      "GET " + path + " HTTP/1.1\r\nHost: 127.0.0.1\r\nConnection: close\r\n\r\n";
  std::string reply;
  if (::send(fd, request.data(), request.size(), MSG_NOSIGNAL) == ssize_t(request.size())) {
    char chunk[8192];
    ssize_t n = 0;
    while ((n = ::recv(fd, chunk, sizeof chunk, 0)) > 0)
      reply.append(chunk, static_cast<std::size_t>(n));
  }
  ::close(fd);
  const auto body = reply.find("\r\n\r\n");
  if (reply.rfind("HTTP/1.1 200", 0) != 0 || body == std::string::npos)
    throw std::runtime_error("GET " + path + ": " + reply.substr(0, reply.find('\r')));
  return reply.substr(body + 4);
}

std::optional<double> metricValue(const std::string& exposition, const std::string& series) {
  std::istringstream lines(exposition);
  std::string line;
  while (std::getline(lines, line))
    if (line.size() > series.size() && line.rfind(series, 0) == 0 && line[series.size()] == ' ')
      return std::stod(line.substr(series.size() + 1));
  return std::nullopt;
}

int readHttpPort(const std::string& portFile, std::chrono::milliseconds timeout) {
  const auto until = std::chrono::steady_clock::now() + timeout;
  do {
    std::stringstream content;
    content << std::ifstream(portFile).rdbuf();
    const std::string text = content.str();  // complete once the newline is there
    if (!text.empty() && text.back() == '\n') return std::stoi(text);
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  } while (std::chrono::steady_clock::now() < until);
  return 0;
}

std::string writeStationFile(const std::string& dir, const std::string& camera, int plcPort,
                             const std::string& plcMode, const std::string& plcOptions) {
  const std::string recipes = std::string(FACET_SOURCE_DIR) + "/recipes";
  std::ofstream f(dir + "/station.yaml");
  f << "schema_version: 1\nname: integration-station\ncamera:\n" << camera;
  f << "  scans:\n    folder: " << recipes << "/demo/scan_offset\n    glob: \"*.csv\"\n";
  {  // facetd --no-plc ignores the section, but the station file needs one
    f << "plc:\n  role: client\n  mode: " << plcMode << "\n  transport: tcp\n  host: 127.0.0.1\n"
      << "  port: " << (plcPort > 0 ? plcPort : 502) << "\n  unit_id: 1\n  word_order: ABCD\n"
      << "  response_timeout_ms: 500\n  heartbeat_period_ms: 1000\n"
      << plcOptions << "  register_map:\n    address_base: 0\n    control:\n"
      << "      trigger: {coil: 0}\n      result_ack: {coil: 1}\n"
      << "      recipe_select: {register: 0}\n    status:\n"
      << "      ready: {coil: 16}\n      busy: {coil: 17}\n      result_valid: {coil: 18}\n"
      << "      pass: {coil: 19}\n      completed_toggle: {coil: 20}\n"
      << "      missed_trigger: {coil: 21}\n      error: {coil: 22}\n"
      << "      error_code: {register: 10}\n      heartbeat: {register: 11}\n"
      << "      inspection_counter: {register: 12}\n      active_recipe: {register: 13}\n";
  }
  f << "recipes: " << recipes << "\n";
  f << "results:\n  database: " << dir << "/results.db\n";
  f << "archive:\n  folder: " << dir << "/archive\n  quota_mb: 50\n  keep: fail\n";
  f << "http:\n  bind: 127.0.0.1\n  port: 0\n";
  f << "calibration:\n  file: " << recipes << "/calibration.yaml\n";
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
