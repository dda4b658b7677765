#pragma once
// PostgresCluster: a throw-away PostgreSQL cluster made by the test with Debian's server
// binaries (initdb, postgres) in a temporary folder, listening on 127.0.0.1 on a free port with
// password authentication. The server refuses to run as root, so as root (CI, containers) it
// runs as the `postgres` system user the Debian package creates (through setpriv, which execs
// without forking: the test kills the real postmaster).

#include <memory>
#include <string>

#include "tests/daemon/child_process.hpp"

struct pg_conn;

namespace facet::sinks_test {

class PostgresCluster {
 public:
  // Creates the cluster, a role `station` (password `station-password`) and its database
  // `facet`. Throws std::runtime_error with the reason when it cannot.
  explicit PostgresCluster(const std::string& folder);
  ~PostgresCluster();

  void start();  // waits until the server accepts connections
  void kill();   // SIGKILL of the postmaster: a crash, no shutdown checkpoint
  [[nodiscard]] int port() const { return port_; }
  // A libpq connection string for the role `station` (without its password).
  [[nodiscard]] std::string connection() const;
  static constexpr const char* kPassword = "station-password";
  // Runs `sql` as `station` and returns the first column of the first row ("" when none).
  [[nodiscard]] std::string query(const std::string& sql) const;

 private:
  std::vector<std::string> asServerUser(std::vector<std::string> argv) const;
  std::string folder_;
  std::string bin_;
  int port_;
  std::unique_ptr<daemon_test::ChildProcess> server_;
};

}  // namespace facet::sinks_test
