#include "tests/sinks/postgres_cluster.hpp"

#include <libpq-fe.h>
#include <pwd.h>
#include <unistd.h>

#include <csignal>

#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <thread>

#include "tests/plc/pymodbus_peer.hpp"

namespace facet::sinks_test {
namespace {

using namespace std::chrono_literals;
constexpr const char* kAdminPassword = "admin-password";

// The newest server installed by Debian's postgresql package.
std::string serverBinaries() {
  std::string best;
  std::error_code ec;
  for (const auto& e : std::filesystem::directory_iterator("/usr/lib/postgresql", ec))
    if (std::filesystem::exists(e.path() / "bin/postgres") && e.path().string() > best)
      best = e.path().string();
  if (best.empty())
    throw std::runtime_error(
        "no PostgreSQL server under /usr/lib/postgresql: install the Debian package postgresql "
        "(deploy/install-deps.sh)");
  return best + "/bin";
}

void run(const std::vector<std::string>& argv, const std::string& log) {
  daemon_test::ChildProcess p(argv, {}, log);
  const auto rc = p.wait(120s);
  if (rc != 0) {
    std::ifstream in(log);
    throw std::runtime_error(argv[0] + " failed:\n" +
                             std::string(std::istreambuf_iterator<char>(in), {}));
  }
}

}  // namespace

std::vector<std::string> PostgresCluster::asServerUser(std::vector<std::string> argv) const {
  if (::geteuid() != 0) return argv;
  std::vector<std::string> wrapped{"/usr/bin/setpriv", "--reuid=postgres", "--regid=postgres",
                                   "--clear-groups", "--"};
  wrapped.insert(wrapped.end(), argv.begin(), argv.end());
  return wrapped;
}

PostgresCluster::PostgresCluster(const std::string& folder)
    : folder_(folder + "/pg"), bin_(serverBinaries()), port_(plc::test::freeTcpPort()) {
  std::filesystem::create_directories(folder_);
  { std::ofstream(folder_ + "/admin-password") << kAdminPassword << "\n"; }
  if (::geteuid() == 0) {
    const passwd* pw = ::getpwnam("postgres");
    if (!pw)
      throw std::runtime_error("running as root and there is no user 'postgres' to run the server");
    // The test's folder is root's; the server's own folder belongs to the server's user.
    for (const auto& p : {folder, folder_, folder_ + "/admin-password"})
      if (::chown(p.c_str(), pw->pw_uid, pw->pw_gid) != 0)
        throw std::runtime_error("cannot hand " + p + " to user postgres");
  }
  run(asServerUser({bin_ + "/initdb", "-D", folder_ + "/data", "-U", "admin", "--auth-local=trust",
                    "--auth-host=scram-sha-256", "--pwfile=" + folder_ + "/admin-password",
                    "--no-sync", "-E", "UTF8", "--locale=C"}),
      folder + "/initdb.log");
  start();
  const std::string admin = "host=127.0.0.1 port=" + std::to_string(port_) +
                            " user=admin dbname=postgres password=" + kAdminPassword;
  PGconn* c = PQconnectdb(admin.c_str());
  for (const std::string& sql :
       {std::string("CREATE ROLE station LOGIN PASSWORD '") + kPassword + "'",
        std::string("CREATE DATABASE facet OWNER station")}) {
    PGresult* r = PQexec(c, sql.c_str());
    const bool ok = PQresultStatus(r) == PGRES_COMMAND_OK;
    PQclear(r);
    if (!ok) {
      const std::string why = PQerrorMessage(c);
      PQfinish(c);
      throw std::runtime_error(sql + ": " + why);
    }
  }
  PQfinish(c);
}

PostgresCluster::~PostgresCluster() {
  kill();
}

void PostgresCluster::start() {
  const auto until = std::chrono::steady_clock::now() + 60s;
  const std::string ping = "host=127.0.0.1 port=" + std::to_string(port_) + " dbname=postgres";
  while (std::chrono::steady_clock::now() < until) {
    if (!server_)
      server_ = std::make_unique<daemon_test::ChildProcess>(
          asServerUser({bin_ + "/postgres", "-D", folder_ + "/data", "-p", std::to_string(port_),
                        "-k", folder_, "-c", "listen_addresses=127.0.0.1", "-c", "fsync=off"}),
          std::map<std::string, std::string>{}, folder_ + "/server.log");
    if (PQping(ping.c_str()) == PQPING_OK) return;
    // After a kill the old backends may still hold the shared memory for a moment: try again.
    if (server_->wait(0ms)) server_.reset();
    std::this_thread::sleep_for(50ms);
  }
  std::ifstream in(folder_ + "/server.log");
  throw std::runtime_error("PostgreSQL did not start on port " + std::to_string(port_) + ":\n" +
                           std::string(std::istreambuf_iterator<char>(in), {}));
}

void PostgresCluster::kill() {
  if (!server_) return;
  server_->signal(SIGKILL);
  server_->wait(10s);
  server_.reset();
}

std::string PostgresCluster::connection() const {
  return "host=127.0.0.1 port=" + std::to_string(port_) + " dbname=facet user=station";
}

std::string PostgresCluster::query(const std::string& sql) const {
  const std::string conninfo = connection() + " password=" + kPassword;
  PGconn* c = PQconnectdb(conninfo.c_str());
  PGresult* r = PQexec(c, sql.c_str());
  std::string value;
  if (PQresultStatus(r) != PGRES_TUPLES_OK) {
    const std::string why = PQerrorMessage(c);
    PQclear(r);
    PQfinish(c);
    throw std::runtime_error(sql + ": " + why);
  }
  if (PQntuples(r) > 0) value = PQgetvalue(r, 0, 0);
  PQclear(r);
  PQfinish(c);
  return value;
}

}  // namespace facet::sinks_test
