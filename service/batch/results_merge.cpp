#include "service/batch/results_merge.hpp"

#include <sqlite3.h>

#include <stdexcept>
#include <string>

#include "service/daemon/results_store.hpp"

namespace facet::service {
namespace {

constexpr const char* kValueColumns =
    "part_id, name, value, unit, nominal, tol_minus, tol_plus, checked, pass";

class Database {
 public:
  explicit Database(const std::filesystem::path& file) : file_(file) {
    if (sqlite3_open_v2(file.c_str(), &db_, SQLITE_OPEN_READWRITE, nullptr) != SQLITE_OK) {
      const std::string why = db_ ? sqlite3_errmsg(db_) : "cannot open";
      sqlite3_close(db_);
      throw std::runtime_error(file.string() + ": " + why);
    }
  }
  ~Database() { sqlite3_close(db_); }
  Database(const Database&) = delete;
  Database& operator=(const Database&) = delete;

  void exec(const std::string& sql, const std::filesystem::path& about) {
    char* err = nullptr;
    if (sqlite3_exec(db_, sql.c_str(), nullptr, nullptr, &err) != SQLITE_OK) {
      const std::string why = err ? err : "unknown error";
      sqlite3_free(err);
      throw std::runtime_error(about.string() + ": " + why);
    }
  }
  void tryExec(const char* sql) { sqlite3_exec(db_, sql, nullptr, nullptr, nullptr); }
  std::int64_t number(const std::string& sql) {
    sqlite3_stmt* s = nullptr;
    std::int64_t v = -1;
    if (sqlite3_prepare_v2(db_, sql.c_str(), -1, &s, nullptr) == SQLITE_OK &&
        sqlite3_step(s) == SQLITE_ROW)
      v = sqlite3_column_int64(s, 0);
    sqlite3_finalize(s);
    return v;
  }
  std::int64_t changes() { return sqlite3_changes64(db_); }

 private:
  std::filesystem::path file_;
  sqlite3* db_ = nullptr;
};

std::string quoted(const std::filesystem::path& p) {
  std::string q = "'";
  for (const char c : p.string()) q += c == '\'' ? std::string("''") : std::string(1, c);
  return q + "'";
}

}  // namespace

std::vector<MergedInput> mergeResults(const std::vector<std::filesystem::path>& inputs,
                                      const std::filesystem::path& out) {
  if (inputs.empty()) throw std::runtime_error("results merge: no input files");
  if (std::filesystem::exists(out))
    throw std::runtime_error(out.string() + ": exists already; merge writes a new file");
  for (const auto& in : inputs)
    if (!std::filesystem::is_regular_file(in))
      throw std::runtime_error(in.string() + ": no such results database");
  std::vector<MergedInput> merged;
  try {
    { ResultsStore create(out); }  // the store's own schema
    Database db(out);
    for (const auto& in : inputs) {
      db.exec("ATTACH DATABASE " + quoted(in) + " AS source", in);
      try {
        if (db.number("SELECT count(*) FROM source.sqlite_master WHERE type = 'table' AND name "
                      "IN ('parts', 'measurements')") != 2)
          throw std::runtime_error(in.string() + ": not a facet results database");
        const std::int64_t repeated = db.number(
            "SELECT part_id FROM source.parts WHERE part_id IN (SELECT part_id FROM main.parts) "
            "LIMIT 1");
        if (repeated >= 0)
          throw std::runtime_error(in.string() + ": part " + std::to_string(repeated) +
                                   " is in an earlier input too (overlapping shards, or the same "
                                   "file twice?)");
        MergedInput m{in};
        db.exec("BEGIN", out);
        // A shard written before parts had a later column gives '' for it.
        std::string columns = kStoredPartColumns;
        for (const std::string column : kLaterPartColumns)
          if (db.number("SELECT count(*) FROM pragma_table_info('parts', 'source') WHERE name = '" +
                        column + "'") == 0)
            columns.replace(columns.rfind(column), column.size(), "''");
        db.exec(std::string("INSERT INTO main.parts (") + kStoredPartColumns + ") SELECT " +
                    columns + " FROM source.parts",
                in);
        m.parts = db.changes();
        db.exec(std::string("INSERT INTO main.measurements (") + kValueColumns + ") SELECT " +
                    kValueColumns + " FROM source.measurements",
                in);
        m.measurements = db.changes();
        db.exec("COMMIT", out);
        merged.push_back(m);
      } catch (...) {
        db.tryExec("ROLLBACK");
        db.tryExec("DETACH DATABASE source");
        throw;
      }
      db.exec("DETACH DATABASE source", in);
    }
  } catch (...) {
    std::error_code ec;
    for (const char* suffix : {"", "-wal", "-shm"})
      std::filesystem::remove(out.string() + suffix, ec);
    throw;
  }
  return merged;
}

}  // namespace facet::service
