#include "service/daemon/results_store.hpp"

#include "service/daemon/part_export.hpp"

#include <sqlite3.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <set>
#include <sstream>
#include <stdexcept>

namespace facet::service {

namespace {

std::int64_t toMicros(std::chrono::system_clock::time_point t) {
  return std::chrono::duration_cast<std::chrono::microseconds>(t.time_since_epoch()).count();
}

std::chrono::system_clock::time_point fromMicros(std::int64_t us) {
  return std::chrono::system_clock::time_point(std::chrono::microseconds(us));
}

// A prepared statement that finalises itself.
class Statement {
 public:
  Statement(sqlite3* db, const std::string& sql, const std::filesystem::path& file) : db_(db) {
    if (sqlite3_prepare_v2(db, sql.c_str(), -1, &stmt_, nullptr) != SQLITE_OK)
      throw std::runtime_error(file.string() + ": " + sqlite3_errmsg(db));
  }
  ~Statement() { sqlite3_finalize(stmt_); }
  Statement(const Statement&) = delete;
  Statement& operator=(const Statement&) = delete;
  sqlite3_stmt* get() { return stmt_; }
  void bind(int i, std::int64_t v) { sqlite3_bind_int64(stmt_, i, v); }
  void bind(int i, double v) { sqlite3_bind_double(stmt_, i, v); }
  void bind(int i, const std::string& v) {
    sqlite3_bind_text(stmt_, i, v.c_str(), static_cast<int>(v.size()), SQLITE_TRANSIENT);
  }
  void bindNull(int i) { sqlite3_bind_null(stmt_, i); }
  bool step() {
    const int rc = sqlite3_step(stmt_);
    if (rc == SQLITE_ROW) return true;
    if (rc == SQLITE_DONE) return false;
    throw std::runtime_error(std::string("sqlite: ") + sqlite3_errmsg(db_));
  }
  std::string text(int col) {
    const auto* p = sqlite3_column_text(stmt_, col);
    return p ? reinterpret_cast<const char*>(p) : "";
  }

 private:
  sqlite3* db_;
  sqlite3_stmt* stmt_ = nullptr;
};

void exec(sqlite3* db, const char* sql, const std::filesystem::path& file) {
  char* err = nullptr;
  if (sqlite3_exec(db, sql, nullptr, nullptr, &err) != SQLITE_OK) {
    std::string msg = err ? err : "unknown error";
    sqlite3_free(err);
    throw std::runtime_error(file.string() + ": " + msg);
  }
}

bool hasColumn(sqlite3* db, const char* table, const char* column,
               const std::filesystem::path& file) {
  Statement q(
      db, std::string("SELECT count(*) FROM pragma_table_info('") + table + "') WHERE name = ?1",
      file);
  q.bind(1, std::string(column));
  q.step();
  return sqlite3_column_int64(q.get(), 0) > 0;
}

constexpr const char* kSchema = R"sql(
CREATE TABLE IF NOT EXISTS parts (
  part_id        INTEGER PRIMARY KEY,
  time_us        INTEGER NOT NULL,
  time_utc       TEXT NOT NULL,
  recipe_id      INTEGER NOT NULL,
  recipe_name    TEXT NOT NULL,
  recipe_version TEXT NOT NULL,
  frame_id       INTEGER NOT NULL,
  source         TEXT NOT NULL,
  serial         TEXT NOT NULL,
  expected       TEXT NOT NULL,
  verdict        TEXT NOT NULL CHECK (verdict IN ('pass', 'fail', 'error')),
  failed_checks  TEXT NOT NULL,
  error          TEXT NOT NULL,
  inspection_ms  REAL NOT NULL,
  timings_json   TEXT NOT NULL,
  defect         TEXT NOT NULL DEFAULT '',
  notes          TEXT NOT NULL DEFAULT ''  -- one note a line
);
CREATE INDEX IF NOT EXISTS parts_time ON parts(time_us);
CREATE TABLE IF NOT EXISTS measurements (
  part_id   INTEGER NOT NULL REFERENCES parts(part_id) ON DELETE CASCADE,
  name      TEXT NOT NULL,
  value     REAL,
  unit      TEXT NOT NULL,
  nominal   REAL,
  tol_minus REAL,
  tol_plus  REAL,
  checked   INTEGER NOT NULL,
  pass      INTEGER NOT NULL,
  PRIMARY KEY (part_id, name)
);
)sql";

}  // namespace

ResultsStore::ResultsStore(const std::filesystem::path& file, RetentionPolicy retention)
    : file_(file), retention_(retention) {
  if (!file.parent_path().empty()) std::filesystem::create_directories(file.parent_path());
  if (sqlite3_open_v2(file.c_str(), &db_, SQLITE_OPEN_READWRITE | SQLITE_OPEN_CREATE, nullptr) !=
      SQLITE_OK) {
    const std::string msg = db_ ? sqlite3_errmsg(db_) : "cannot open";
    sqlite3_close(db_);
    db_ = nullptr;
    throw std::runtime_error(file.string() + ": " + msg);
  }
  sqlite3_busy_timeout(db_, 2000);
  try {
    // WAL: readers (HTTP, export) never block the writer, and a killed process leaves a
    // consistent file. synchronous=NORMAL is durable across process crashes in WAL mode.
    exec(db_, "PRAGMA journal_mode=WAL; PRAGMA synchronous=NORMAL; PRAGMA foreign_keys=ON;", file_);
    // facetd's store mostly appends one part at a time and reads back the newest ones. SQLite's
    // default page cache (2 MiB) keeps every page written until it is full, so facetd's memory
    // grew by ~1 KiB per part over its first ~2,500 parts; 512 KiB holds the tables' tails and
    // lets memory settle within the first few hundred parts (scans are served by the OS's cache).
    exec(db_, "PRAGMA cache_size=-512;", file_);
    exec(db_, kSchema, file_);
    // A store written before parts had `defect` (the recorded part's known fault) or `notes`
    // gains them.
    for (const char* column : kLaterPartColumns)
      if (!hasColumn(db_, "parts", column, file_))
        exec(db_,
             (std::string("ALTER TABLE parts ADD COLUMN ") + column + " TEXT NOT NULL DEFAULT ''")
                 .c_str(),
             file_);
  } catch (...) {
    sqlite3_close(db_);
    db_ = nullptr;
    throw;
  }
}

ResultsStore::~ResultsStore() {
  sqlite3_close(db_);
}

void ResultsStore::store(const PartResult& part) {
  exec(db_, "BEGIN", file_);
  try {
    Statement insert(db_,
                     "INSERT INTO parts (" + std::string(kStoredPartColumns) +
                         ") VALUES (?1, ?2, ?3, ?4, ?5, ?6, ?7, ?8, ?9, ?10, ?11, ?12, ?13, ?14, "
                         "?15, ?16, ?17)",
                     file_);
    insert.bind(1, static_cast<std::int64_t>(part.partId));
    insert.bind(2, toMicros(part.time));
    insert.bind(3, isoTime(part.time));
    insert.bind(4, static_cast<std::int64_t>(part.recipeId));
    insert.bind(5, part.recipeName);
    insert.bind(6, part.recipeVersion);
    insert.bind(7, static_cast<std::int64_t>(part.frameId));
    insert.bind(8, part.source);
    insert.bind(9, part.serial);
    insert.bind(10, part.expectedVerdict);
    insert.bind(11, std::string(verdictName(part.verdict)));
    insert.bind(12, joinedChecks(part.failedChecks, ','));
    insert.bind(13, part.error);
    insert.bind(14, part.inspectionMs);
    insert.bind(15, timingsText(part.timings));
    insert.bind(16, part.recordedDefect);
    insert.bind(17, joinedChecks(part.notes, '\n'));
    insert.step();
    Statement value(db_, "INSERT INTO measurements VALUES (?1, ?2, ?3, ?4, ?5, ?6, ?7, ?8, ?9)",
                    file_);
    for (const auto& m : part.measurements) {
      sqlite3_reset(value.get());
      value.bind(1, static_cast<std::int64_t>(part.partId));
      value.bind(2, m.name);
      if (std::isfinite(m.value))
        value.bind(3, m.value);
      else
        value.bindNull(3);
      value.bind(4, m.unit);
      auto bindOptional = [&](int i, const std::optional<double>& v) {
        if (v)
          value.bind(i, *v);
        else
          value.bindNull(i);
      };
      bindOptional(5, m.nominal);
      bindOptional(6, m.tolMinus);
      bindOptional(7, m.tolPlus);
      value.bind(8, static_cast<std::int64_t>(m.checked));
      value.bind(9, static_cast<std::int64_t>(m.pass));
      value.step();
    }
    exec(db_, "COMMIT", file_);
  } catch (...) {
    sqlite3_exec(db_, "ROLLBACK", nullptr, nullptr, nullptr);
    throw;
  }
}

std::int64_t ResultsStore::applyRetention(std::chrono::system_clock::time_point now,
                                          std::int64_t limit) {
  std::int64_t deleted = 0;
  // SQLite's LIMIT -1 is no limit.
  auto remaining = [&] { return limit > 0 ? limit - deleted : std::int64_t{-1}; };
  // The newest part always stays: the next part id after a restart continues from it.
  if (retention_.maxAge) {
    Statement del(db_,
                  "DELETE FROM parts WHERE part_id IN (SELECT part_id FROM parts "
                  "WHERE time_us < ?1 AND part_id < (SELECT MAX(part_id) FROM parts) "
                  "ORDER BY part_id LIMIT ?2)",
                  file_);
    del.bind(1, toMicros(now - *retention_.maxAge));
    del.bind(2, remaining());
    del.step();
    deleted += sqlite3_changes64(db_);
  }
  if (retention_.maxParts && remaining() != 0) {
    // Walks the primary key from the newest part: no scan of the whole table.
    Statement del(db_,
                  "DELETE FROM parts WHERE part_id IN (SELECT part_id FROM parts "
                  "WHERE part_id <= (SELECT part_id FROM parts ORDER BY part_id DESC LIMIT 1 "
                  "OFFSET ?1) ORDER BY part_id LIMIT ?2)",
                  file_);
    del.bind(1, std::max<std::int64_t>(*retention_.maxParts, 1));
    del.bind(2, remaining());
    del.step();
    deleted += sqlite3_changes64(db_);
  }
  return deleted;
}

std::int64_t ResultsStore::partCount() const {
  Statement q(db_, "SELECT COUNT(*) FROM parts", file_);
  q.step();
  return sqlite3_column_int64(q.get(), 0);
}

std::uint64_t ResultsStore::lastPartId() const {
  Statement q(db_, "SELECT COALESCE(MAX(part_id), 0) FROM parts", file_);
  q.step();
  return static_cast<std::uint64_t>(sqlite3_column_int64(q.get(), 0));
}

std::vector<PartResult> ResultsStore::select(const std::string& where, const std::string& order,
                                             std::int64_t bind, std::size_t limit) const {
  std::string sql =
      "SELECT part_id, time_us, recipe_id, recipe_name, recipe_version, frame_id, source, serial, "
      "expected, verdict, failed_checks, error, inspection_ms, timings_json, defect, notes FROM "
      "parts " +
      where + " ORDER BY part_id " + order;
  if (limit > 0) sql += " LIMIT " + std::to_string(limit);
  Statement q(db_, sql, file_);
  if (!where.empty()) q.bind(1, bind);
  std::vector<PartResult> parts;
  std::map<std::int64_t, std::size_t> index;
  while (q.step()) {
    PartResult p;
    p.partId = static_cast<std::uint64_t>(sqlite3_column_int64(q.get(), 0));
    p.time = fromMicros(sqlite3_column_int64(q.get(), 1));
    p.recipeId = sqlite3_column_int(q.get(), 2);
    p.recipeName = q.text(3);
    p.recipeVersion = q.text(4);
    p.frameId = static_cast<std::uint64_t>(sqlite3_column_int64(q.get(), 5));
    p.source = q.text(6);
    p.serial = q.text(7);
    p.expectedVerdict = q.text(8);
    p.verdict = verdictFromName(q.text(9));
    p.failedChecks = splitList(q.text(10), ',');
    p.error = q.text(11);
    p.inspectionMs = sqlite3_column_double(q.get(), 12);
    p.timings = timingsFromText(q.text(13));
    p.recordedDefect = q.text(14);
    p.notes = splitList(q.text(15), '\n');
    index[static_cast<std::int64_t>(p.partId)] = parts.size();
    parts.push_back(std::move(p));
  }
  if (parts.empty()) return parts;
  Statement m(db_,
              "SELECT part_id, name, value, unit, nominal, tol_minus, tol_plus, checked, pass "
              "FROM measurements WHERE part_id BETWEEN ?1 AND ?2 ORDER BY part_id, rowid",
              file_);
  m.bind(1, index.begin()->first);
  m.bind(2, index.rbegin()->first);
  while (m.step()) {
    const auto it = index.find(sqlite3_column_int64(m.get(), 0));
    if (it == index.end()) continue;
    Measurement v;
    v.name = m.text(1);
    v.value = sqlite3_column_type(m.get(), 2) == SQLITE_NULL ? std::nan("")
                                                             : sqlite3_column_double(m.get(), 2);
    v.unit = m.text(3);
    auto optional = [&](int col) -> std::optional<double> {
      if (sqlite3_column_type(m.get(), col) == SQLITE_NULL) return std::nullopt;
      return sqlite3_column_double(m.get(), col);
    };
    v.nominal = optional(4);
    v.tolMinus = optional(5);
    v.tolPlus = optional(6);
    v.checked = sqlite3_column_int(m.get(), 7) != 0;
    v.pass = sqlite3_column_int(m.get(), 8) != 0;
    parts[it->second].measurements.push_back(std::move(v));
  }
  return parts;
}

std::vector<PartResult> ResultsStore::query(std::chrono::system_clock::time_point since,
                                            std::size_t limit) const {
  return select("WHERE time_us >= ?1", "ASC", toMicros(since), limit);
}

std::vector<PartResult> ResultsStore::partsAfter(std::uint64_t afterPartId,
                                                 std::size_t limit) const {
  return select("WHERE part_id > ?1", "ASC", static_cast<std::int64_t>(afterPartId), limit);
}

std::vector<PartResult> ResultsStore::latest(std::size_t count) const {
  auto parts = select("", "DESC", 0, count);
  std::reverse(parts.begin(), parts.end());
  return parts;
}

std::string ResultsStore::integrityCheck() const {
  Statement q(db_, "PRAGMA integrity_check", file_);
  return q.step() ? q.text(0) : "no answer";
}

}  // namespace facet::service
