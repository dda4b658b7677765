#include "service/sinks/postgres_connection.hpp"

#include <stdexcept>

namespace facet::service {

PgResult executeWithText(PGconn* conn, const char* sql,
                         const std::vector<std::optional<std::string>>& params) {
  std::vector<const char*> values;
  for (const auto& p : params) values.push_back(p ? p->c_str() : nullptr);
  return PgResult(config::libpq().execParams(conn, sql, static_cast<int>(values.size()), nullptr,
                                             values.data(), nullptr, nullptr, 0));
}

bool succeeded(const PgResult& r) {
  const auto s = config::libpq().resultStatus(r.get());
  return s == PGRES_COMMAND_OK || s == PGRES_TUPLES_OK;
}

std::string postgresPeer(const std::string& connection) {
  char* error = nullptr;
  const config::LibPq& pq = config::libpq();
  std::unique_ptr<PQconninfoOption, decltype(config::LibPq::conninfoFree)> options(
      pq.conninfoParse(connection.c_str(), &error), pq.conninfoFree);
  pq.freemem(error);
  std::string host = "localhost", port = "5432", db;
  for (auto* o = options.get(); o && o->keyword; ++o) {
    if (!o->val) continue;
    const std::string k = o->keyword;
    if (k == "host" || k == "hostaddr") host = o->val;
    if (k == "port") port = o->val;
    if (k == "dbname") db = o->val;
  }
  return host + ":" + port + "/" + db;
}

std::string postgresError(const PGconn* conn) {
  std::string s = config::libpq().errorMessage(conn);
  while (!s.empty() && (s.back() == '\n' || s.back() == ' ')) s.pop_back();
  return s;
}

PgConnection connectOrThrow(const std::string& connection) {
  const config::LibPq& pq = config::libpq();
  PgConnection conn(pq.connectdb(connection.c_str()));
  if (pq.status(conn.get()) != CONNECTION_OK)
    throw std::runtime_error("postgres " + postgresPeer(connection) +
                             ": cannot connect: " + postgresError(conn.get()));
  return conn;
}

}  // namespace facet::service
