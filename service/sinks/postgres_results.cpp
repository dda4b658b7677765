#include "service/sinks/postgres_results.hpp"

#include <cmath>
#include <map>
#include <sstream>
#include <stdexcept>

#include "config/libpq_library.hpp"
#include "service/daemon/part_export.hpp"
#include "service/sinks/postgres_connection.hpp"

namespace facet::service {

namespace {

std::optional<double> number(const config::LibPq& pq, const PGresult* r, int row, int column) {
  if (pq.getisnull(r, row, column)) return std::nullopt;
  return std::stod(pq.getvalue(r, row, column));
}

}  // namespace

std::vector<StationPart> readPostgresResults(const std::string& connection,
                                             const std::optional<std::string>& station,
                                             std::chrono::system_clock::time_point since,
                                             std::size_t limit) {
  const config::LibPq& pq = config::libpq();
  const std::string peer = postgresPeer(connection);
  const PgConnection conn = connectOrThrow(connection);
  auto fail = [&](const std::string& what) {
    return std::runtime_error("postgres " + peer + ": " + what + ": " + postgresError(conn.get()));
  };
  const std::string sinceUs = std::to_string(
      std::chrono::duration_cast<std::chrono::microseconds>(since.time_since_epoch()).count());
  // A temporary table of the chosen parts, so that their measurements are read with one join.
  std::string chosen =
      "CREATE TEMP TABLE chosen AS SELECT * FROM parts WHERE time_us >= $1::bigint AND ($2::text "
      "IS NULL OR station = $2) ORDER BY time_us, station, part_id";
  if (limit > 0) chosen += " LIMIT " + std::to_string(limit);
  if (!succeeded(executeWithText(conn.get(), chosen.c_str(), {sinceUs, station})))
    throw fail("cannot read the parts (is this facet's results database?)");

  const PgResult parts(pq.exec(
      conn.get(),
      "SELECT station, part_id, time_us, recipe_id, recipe_name, recipe_version, frame_id, "
      "source, serial, expected, verdict, failed_checks, error, inspection_ms, timings_json, "
      "defect, notes FROM chosen ORDER BY time_us, station, part_id"));
  if (!succeeded(parts)) throw fail("cannot read the parts");
  std::vector<StationPart> out;
  std::map<std::tuple<std::string, std::string, std::string>, std::size_t> index;
  const PGresult* r = parts.get();
  for (int i = 0; i < pq.ntuples(r); ++i) {
    auto text = [&](int c) { return std::string(pq.getvalue(r, i, c)); };
    StationPart s;
    s.station = text(0);
    PartResult& p = s.part;
    p.partId = std::stoull(text(1));
    p.time = std::chrono::system_clock::time_point(std::chrono::microseconds(std::stoll(text(2))));
    p.recipeId = std::stoi(text(3));
    p.recipeName = text(4);
    p.recipeVersion = text(5);
    p.frameId = std::stoull(text(6));
    p.source = text(7);
    p.serial = text(8);
    p.expectedVerdict = text(9);
    p.verdict = verdictFromName(text(10));
    p.failedChecks = splitList(text(11), ',');
    p.error = text(12);
    p.inspectionMs = std::stod(text(13));
    p.timings = timingsFromText(text(14));
    p.recordedDefect = text(15);
    p.notes = splitList(text(16), '\n');
    index[{s.station, text(1), text(2)}] = out.size();
    out.push_back(std::move(s));
  }

  const PgResult values(pq.exec(
      conn.get(),
      "SELECT m.station, m.part_id, m.time_us, m.name, m.value, m.unit, m.nominal, m.tol_minus, "
      "m.tol_plus, m.checked, m.pass FROM measurements m JOIN chosen c USING (station, part_id, "
      "time_us) ORDER BY m.ctid"));
  if (!succeeded(values)) throw fail("cannot read the measurements");
  const PGresult* v = values.get();
  for (int i = 0; i < pq.ntuples(v); ++i) {
    const auto it = index.find({pq.getvalue(v, i, 0), pq.getvalue(v, i, 1), pq.getvalue(v, i, 2)});
    if (it == index.end()) continue;
    Measurement m;
    m.name = pq.getvalue(v, i, 3);
    m.value = number(pq, v, i, 4).value_or(std::nan(""));
    m.unit = pq.getvalue(v, i, 5);
    m.nominal = number(pq, v, i, 6);
    m.tolMinus = number(pq, v, i, 7);
    m.tolPlus = number(pq, v, i, 8);
    m.checked = std::string(pq.getvalue(v, i, 9)) == "t";
    m.pass = std::string(pq.getvalue(v, i, 10)) == "t";
    out[it->second].part.measurements.push_back(std::move(m));
  }
  return out;
}

}  // namespace facet::service
