#pragma once
// PymodbusPlc: runs tests/plc/pymodbus_plc.py (a pymodbus TCP server plus a small PLC program)
// as a child process: the independent Modbus peer of the PLC integration tests.

#include <sys/types.h>

#include <chrono>
#include <condition_variable>
#include <functional>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include <nlohmann/json.hpp>

#include "plc/register_map.hpp"

namespace facet::plc::test {

// A TCP port on 127.0.0.1 that was free a moment ago.
int freeTcpPort();

// The peer's JSON config for `map` (wire addresses), written to a temporary file. `options` are
// merged into it (e.g. {"report_writes": true}, see pymodbus_plc.py).
std::string writePeerConfig(const RegisterMap& map, bool freeRun, int registers = 512,
                            int coils = 128,
                            const nlohmann::json& options = nlohmann::json::object());

class PymodbusPlc {
 public:
  // clientMode: the PLC is a Modbus client polling the daemon's server on `port`.
  PymodbusPlc(std::string configPath, int port, bool clientMode = false)
      : configPath_(std::move(configPath)), port_(port), clientMode_(clientMode) {}
  ~PymodbusPlc();

  // Starts the script and waits until it listens (or, in client mode, is connected). Throws
  // std::runtime_error (with the script's message, e.g. "pymodbus is not installed") when it does
  // not.
  void start();
  // SIGKILL, as a PLC losing power: no goodbye on the connection.
  void kill();
  void command(const std::string& line);  // "trigger", "set_register A V"

  // Waits until `done(events)` holds, at most `timeout`; returns whether it held.
  bool waitFor(const std::function<bool(const std::vector<nlohmann::json>&)>& done,
               std::chrono::milliseconds timeout);
  std::vector<nlohmann::json> events(const std::string& kind) const;
  int port() const { return port_; }

 private:
  void readLoop(int fd);

  std::string configPath_;
  int port_;
  bool clientMode_;
  pid_t pid_ = -1;
  int stdinFd_ = -1;
  std::thread reader_;
  mutable std::mutex mutex_;
  std::condition_variable changed_;
  std::vector<nlohmann::json> events_;
  bool exited_ = false;
};

}  // namespace facet::plc::test
