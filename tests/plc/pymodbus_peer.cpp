#include "tests/plc/pymodbus_peer.hpp"

#include <fcntl.h>
#include <netinet/in.h>
#include <signal.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <random>
#include <stdexcept>

namespace facet::plc::test {

namespace {

// Binds a TCP socket to 127.0.0.1:port (0: any) and closes it; the port bound, 0 on failure.
int bindAndRelease(int port) {
  const int s = ::socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
  if (s < 0) return 0;
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  address.sin_port = htons(static_cast<std::uint16_t>(port));
  socklen_t length = sizeof(address);
  const bool bound = ::bind(s, reinterpret_cast<sockaddr*>(&address), sizeof(address)) == 0 &&
                     ::getsockname(s, reinterpret_cast<sockaddr*>(&address), &length) == 0;
  ::close(s);
  return bound ? ntohs(address.sin_port) : 0;
}

// The first port the kernel hands out on its own (net.ipv4.ip_local_port_range).
int ephemeralRangeStart() {
  int low = 32768;
  std::ifstream("/proc/sys/net/ipv4/ip_local_port_range") >> low;
  return low;
}

}  // namespace

// Below the ephemeral range: a port the kernel gives for bind(0) is one it may also give, as
// the local port of any outgoing connection on the machine (the tests' HTTP and Modbus clients,
// other tests), in the time between this check and the peer's bind, which then fails.
int freeTcpPort() {
  constexpr int kLowest = 10000;
  const int end = ephemeralRangeStart();
  if (end > kLowest + 1000) {
    static std::mt19937 random(std::random_device{}());
    std::uniform_int_distribution<int> pick(kLowest, end - 1);
    for (int attempt = 0; attempt < 100; ++attempt)
      if (const int port = bindAndRelease(pick(random)); port > 0) return port;
  }
  return bindAndRelease(0);
}

namespace {
nlohmann::json locationJson(const RegisterMap& map, const Location& at) {
  return {{"table", at.table == Table::Coil ? "coil" : "register"},
          {"address", map.wireAddress(at.address)},
          {"bit", at.bit}};
}
}  // namespace

std::string writePeerConfig(const RegisterMap& map, bool freeRun, int registers, int coils,
                            const nlohmann::json& options) {
  nlohmann::json config = {{"coils", coils},
                           {"registers", registers},
                           {"mode", freeRun ? "free_run" : "triggered"},
                           {"auto_ack", true}};
  nlohmann::json signals = nlohmann::json::object();
  for (const auto& signal : namedSignals(map)) {
    const std::string key = signal.name.substr(signal.name.find('.') + 1);
    signals[key] = locationJson(map, *signal.location);
  }
  config["signals"] = signals;
  nlohmann::json results = nlohmann::json::array();
  for (const auto& output : map.results)
    results.push_back({{"name", output.name},
                       {"address", map.wireAddress(output.address)},
                       {"type", toString(output.type)},
                       {"word_order", toString(output.wordOrder)},
                       {"factor", output.factor}});
  config["results"] = results;
  config.update(options);
  char path[] = "/tmp/facet-plc-peer-XXXXXX";
  const int fd = ::mkstemp(path);
  if (fd < 0) throw std::runtime_error("cannot create a temporary file");
  ::close(fd);
  std::ofstream(path) << config.dump(2);
  return path;
}

PymodbusPlc::~PymodbusPlc() {
  kill();
}

void PymodbusPlc::start() {
  int toChild[2];
  int fromChild[2];
  // CLOEXEC: the child must not inherit these (or the link's socket) beyond exec.
  if (::pipe2(toChild, O_CLOEXEC) != 0 || ::pipe2(fromChild, O_CLOEXEC) != 0)
    throw std::runtime_error("pipe failed");
  ::signal(SIGPIPE, SIG_IGN);
  const std::string script = std::string(FACET_SOURCE_DIR) + "/tests/plc/pymodbus_plc.py";
  const std::string port = std::to_string(port_);
  std::size_t firstEvent = 0;
  {
    std::lock_guard lock(mutex_);
    firstEvent = events_.size();
  }
  pid_ = ::fork();
  if (pid_ == 0) {
    ::dup2(toChild[0], STDIN_FILENO);
    ::dup2(fromChild[1], STDOUT_FILENO);
    ::close(toChild[1]);
    ::close(fromChild[0]);
    ::execl("/usr/bin/python3", "python3", script.c_str(), "--config", configPath_.c_str(),
            "--port", port.c_str(), clientMode_ ? "--client" : static_cast<char*>(nullptr),
            static_cast<char*>(nullptr));
    std::fprintf(stderr, "cannot run /usr/bin/python3\n");
    std::_Exit(127);
  }
  ::close(toChild[0]);
  ::close(fromChild[1]);
  stdinFd_ = toChild[1];
  {
    std::lock_guard lock(mutex_);
    exited_ = false;
  }
  reader_ = std::thread([this, fd = fromChild[0]] { readLoop(fd); });

  std::string failure;
  const bool up = waitFor(
      [&](const std::vector<nlohmann::json>& all) {
        // Only this run's events: after a restart the earlier run's "listening" is still there.
        for (std::size_t i = firstEvent; i < all.size(); ++i) {
          const auto& e = all[i];
          if (e["event"] == "error") failure = e["message"];
          if ((e["event"] == "listening" || e["event"] == "connected") && e["port"] == port_)
            return true;
        }
        return !failure.empty();
      },
      std::chrono::seconds(20));
  bool gone = false;
  {
    std::lock_guard lock(mutex_);
    gone = exited_;
  }
  if (!failure.empty() || !up) {
    kill();
    if (failure.empty())
      failure = gone ? "tests/plc/pymodbus_plc.py exited before listening (is python3-pymodbus "
                       "installed? run deploy/install-deps.sh)"
                     : "tests/plc/pymodbus_plc.py did not listen within 20 s";
    throw std::runtime_error(failure);
  }
  // Events of an earlier run of the same peer (before a restart) stay: tests read them all.
}

void PymodbusPlc::readLoop(int fd) {
  std::string buffer;
  char chunk[4096];
  while (true) {
    const ssize_t n = ::read(fd, chunk, sizeof(chunk));
    if (n <= 0) break;
    buffer.append(chunk, static_cast<std::size_t>(n));
    std::size_t newline;
    while ((newline = buffer.find('\n')) != std::string::npos) {
      const std::string line = buffer.substr(0, newline);
      buffer.erase(0, newline + 1);
      auto parsed = nlohmann::json::parse(line, nullptr, false);
      if (parsed.is_discarded()) continue;
      std::lock_guard lock(mutex_);
      events_.push_back(std::move(parsed));
      changed_.notify_all();
    }
  }
  ::close(fd);
  std::lock_guard lock(mutex_);
  exited_ = true;
  changed_.notify_all();
}

void PymodbusPlc::kill() {
  if (pid_ > 0) {
    ::kill(pid_, SIGKILL);
    ::waitpid(pid_, nullptr, 0);
    pid_ = -1;
  }
  if (stdinFd_ >= 0) {
    ::close(stdinFd_);
    stdinFd_ = -1;
  }
  if (reader_.joinable()) reader_.join();
}

void PymodbusPlc::command(const std::string& line) {
  const std::string text = line + "\n";
  if (stdinFd_ < 0 || ::write(stdinFd_, text.data(), text.size()) != ssize_t(text.size()))
    throw std::runtime_error("the pymodbus PLC is not running");
}

bool PymodbusPlc::waitFor(const std::function<bool(const std::vector<nlohmann::json>&)>& done,
                          std::chrono::milliseconds timeout) {
  std::unique_lock lock(mutex_);
  return changed_.wait_for(lock, timeout, [&] { return done(events_); });
}

std::vector<nlohmann::json> PymodbusPlc::events(const std::string& kind) const {
  std::lock_guard lock(mutex_);
  std::vector<nlohmann::json> out;
  for (const auto& e : events_)
    if (e["event"] == kind) out.push_back(e);
  return out;
}

}  // namespace facet::plc::test
