// facet results export: reads a station's results store or the central PostgreSQL database;
// facet results merge: joins stores.
#include <chrono>
#include <iomanip>
#include <iostream>
#include <optional>
#include <sstream>

#include "service/batch/results_merge.hpp"
#include "service/cli/command_line.hpp"
#include "service/daemon/results_store.hpp"
#include "service/sinks/postgres_results.hpp"

namespace facet::cli {
namespace {

// Accepts an ISO date or date-time in UTC ("2026-11-21", "2026-11-21T08:00:00") or a duration
// back from now ("8h", "30m", "2d").
std::chrono::system_clock::time_point parseSince(const std::string& text) {
  using namespace std::chrono;
  if (text.empty()) return system_clock::time_point{};
  const char unit = text.back();
  if (unit == 'h' || unit == 'm' || unit == 'd' || unit == 's') {
    try {
      const double n = std::stod(text.substr(0, text.size() - 1));
      const double secs = n * (unit == 'd' ? 86400 : unit == 'h' ? 3600 : unit == 'm' ? 60 : 1);
      return system_clock::now() - duration_cast<system_clock::duration>(duration<double>(secs));
    } catch (const std::exception&) {
      throw InputError("--since: cannot read '" + text + "'");
    }
  }
  std::tm tm{};
  std::istringstream in(text);
  in >> std::get_time(&tm, text.size() > 10 ? "%Y-%m-%dT%H:%M:%S" : "%Y-%m-%d");
  if (in.fail())
    throw InputError("--since: expected YYYY-MM-DD[THH:MM:SS] (UTC) or a duration like 8h, got '" +
                     text + "'");
  return system_clock::from_time_t(timegm(&tm));
}

// facet results merge A.db B.db ... --out all.db (service/batch/results_merge.hpp).
void addMergeCommand(CLI::App& results) {
  struct Options {
    std::vector<std::string> inputs;
    std::string out;
    bool json = false;
  };
  auto opt = std::make_shared<Options>();
  auto* merge = results.add_subcommand(
      "merge", "Join results stores (e.g. the shards of a batch re-inspection) into a new one");
  merge->add_option("inputs", opt->inputs, "Results databases (SQLite files)")->required();
  merge->add_option("--out", opt->out, "The merged database to create")->required();
  merge->add_flag("--json", opt->json, "Print a summary as one JSON object");
  merge->callback([opt] {
    std::vector<std::filesystem::path> inputs(opt->inputs.begin(), opt->inputs.end());
    std::vector<service::MergedInput> merged;
    try {
      merged = service::mergeResults(inputs, opt->out);
    } catch (const std::runtime_error& e) {
      throw InputError(e.what());
    }
    std::int64_t parts = 0;
    nlohmann::json list = nlohmann::json::array();
    for (const auto& m : merged) {
      parts += m.parts;
      list.push_back({{"file", m.file.string()}, {"parts", m.parts}});
    }
    if (opt->json) {
      printJson({{"out", opt->out}, {"parts", parts}, {"inputs", list}});
      return;
    }
    for (const auto& m : merged) std::cout << m.file.string() << ": " << m.parts << " parts\n";
    std::cout << opt->out << ": " << parts << " parts\n";
  });
}

// The parts of every station (or of one) from the database the PostgreSQL sinks write.
void exportCentral(const std::string& connection, const std::string& station,
                   std::chrono::system_clock::time_point since, std::size_t limit, bool csv) {
  std::vector<service::StationPart> read;
  try {
    read = service::readPostgresResults(
        connection, station.empty() ? std::nullopt : std::optional(station), since, limit);
  } catch (const std::runtime_error& e) {
    throw InputError(e.what());
  }
  if (csv) {
    std::vector<service::PartResult> parts;
    std::vector<std::string> stations;
    for (auto& s : read) {
      stations.push_back(s.station);
      parts.push_back(std::move(s.part));
    }
    std::cout << service::toCsv(parts, stations);
    return;
  }
  nlohmann::json list = nlohmann::json::array();
  for (const auto& s : read) {
    auto j = service::toJson(s.part);
    j["station"] = s.station;
    list.push_back(std::move(j));
  }
  printJson({{"parts", list}, {"count", read.size()}});
}

}  // namespace

void addResultsCommand(CLI::App& app) {
  auto* results = app.add_subcommand("results", "Read a station's results store");
  results->require_subcommand(1);
  auto* exportCmd = results->add_subcommand(
      "export",
      "Export stored parts as CSV or JSON, from a station's store or the central database");
  struct Options {
    std::string db;
    std::string postgres;
    std::string station;
    std::string since;
    bool csv = false;
    bool json = false;
    std::size_t limit = 0;
  };
  auto opt = std::make_shared<Options>();
  auto* db = exportCmd->add_option("--db", opt->db, "Results database (SQLite file)");
  auto* postgres = exportCmd->add_option(
      "--postgres", opt->postgres,
      "The central PostgreSQL database (a libpq connection string, e.g. \"host=db.plant "
      "dbname=facet user=quality\"; the password from PGPASSWORD or ~/.pgpass)");
  db->excludes(postgres);
  exportCmd->add_option("--station", opt->station, "With --postgres: only this station's parts")
      ->needs(postgres);
  exportCmd->add_option("--since", opt->since,
                        "Only parts at or after: YYYY-MM-DD[THH:MM:SS] UTC, or 8h / 30m / 2d ago");
  exportCmd->add_option("--limit", opt->limit, "At most this many parts (0 = all)");
  auto* csv = exportCmd->add_flag("--csv", opt->csv, "CSV, one column per measured value");
  exportCmd->add_flag("--json", opt->json, "One JSON object {\"parts\": [...]}")->excludes(csv);
  exportCmd->callback([opt] {
    if (!opt->postgres.empty()) {
      exportCentral(opt->postgres, opt->station, parseSince(opt->since), opt->limit, opt->csv);
      return;
    }
    if (opt->db.empty())
      throw InputError("results export needs --db FILE or --postgres CONNECTION");
    if (!std::filesystem::exists(opt->db)) throw InputError(opt->db + ": no such results database");
    const service::ResultsStore store(opt->db);
    const auto parts = store.query(parseSince(opt->since), opt->limit);
    if (opt->csv) {
      std::cout << service::toCsv(parts);
      return;
    }
    nlohmann::json list = nlohmann::json::array();
    for (const auto& p : parts) list.push_back(service::toJson(p));
    printJson({{"parts", list}, {"count", parts.size()}});
  });
  addMergeCommand(*results);
}

}  // namespace facet::cli
