#pragma once
// What the PostgreSQL sink and the results reader share about talking to the server: a result
// that clears itself, parameters sent as text, and how the server and its errors are named in
// messages (never with the password).

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "config/libpq_library.hpp"

namespace facet::service {

struct PgResultDeleter {
  void operator()(PGresult* r) const { config::libpq().clear(r); }
};
using PgResult = std::unique_ptr<PGresult, PgResultDeleter>;

struct PgConnDeleter {
  void operator()(PGconn* c) const { config::libpq().finish(c); }
};
using PgConnection = std::unique_ptr<PGconn, PgConnDeleter>;

// Connects with a libpq connection string; throws std::runtime_error naming the server (never
// the password) and libpq's reason when the server cannot be reached or refuses.
PgConnection connectOrThrow(const std::string& connection);

// PQexecParams with every parameter as text; nullopt is SQL NULL.
PgResult executeWithText(PGconn* conn, const char* sql,
                         const std::vector<std::optional<std::string>>& params);

// The command or query succeeded.
bool succeeded(const PgResult& r);

// host:port/dbname of a connection string, for messages.
std::string postgresPeer(const std::string& connection);

// libpq's last error of `conn` without its trailing newline.
std::string postgresError(const PGconn* conn);

}  // namespace facet::service
