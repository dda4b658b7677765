// facetd under systemd's eyes: the sd_notify protocol on a unix datagram socket this test owns
// (READY, WATCHDOG, RELOADING, STOPPING), a clean exit on SIGTERM with every taken part stored,
// and a SIGKILL that leaves the SQLite store intact for the restarted daemon.
#include <gtest/gtest.h>
#include <poll.h>
#include <sys/socket.h>
#include <sys/un.h>
#include <unistd.h>

#include <csignal>
#include <thread>

#include "tests/daemon/child_process.hpp"
#include "tests/daemon/line_run.hpp"

namespace facet::daemon_test {
namespace {

using namespace std::chrono_literals;
using Clock = std::chrono::steady_clock;

// The socket systemd would listen on: every datagram is one notification.
class NotifySocket {
 public:
  explicit NotifySocket(std::string path) : path_(std::move(path)) {
    fd_ = ::socket(AF_UNIX, SOCK_DGRAM | SOCK_CLOEXEC, 0);
    sockaddr_un address{};
    address.sun_family = AF_UNIX;
    path_.copy(address.sun_path, sizeof(address.sun_path) - 1);
    if (fd_ < 0 || ::bind(fd_, reinterpret_cast<sockaddr*>(&address), sizeof(address)) != 0)
      throw std::runtime_error("cannot bind " + path_);
  }
  ~NotifySocket() { ::close(fd_); }
  const std::string& path() const { return path_; }

  // Waits for a datagram containing `line` (e.g. "READY=1"); every datagram read is kept.
  bool waitFor(const std::string& line, std::chrono::milliseconds timeout) {
    const auto until = Clock::now() + timeout;
    while (Clock::now() < until) {
      pollfd p{fd_, POLLIN, 0};
      const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(until - Clock::now());
      if (::poll(&p, 1, static_cast<int>(std::max<long>(1, left.count()))) <= 0) continue;
      char buf[4096];
      const ssize_t n = ::recv(fd_, buf, sizeof buf, 0);
      if (n <= 0) continue;
      received_.emplace_back(buf, static_cast<std::size_t>(n));
      if (hasLine(received_.back(), line)) return true;
    }
    return false;
  }
  int count(const std::string& line) const {
    int n = 0;
    for (const auto& d : received_) n += hasLine(d, line);
    return n;
  }

 private:
  static bool hasLine(const std::string& datagram, const std::string& line) {
    return ("\n" + datagram + "\n").find("\n" + line + "\n") != std::string::npos;
  }
  std::string path_;
  int fd_ = -1;
  std::vector<std::string> received_;
};

std::string replayCamera() {
  return "  backend: replay\n  replay:\n    folder: " + std::string(FACET_SOURCE_DIR) +
         "/recipes/demo/bracket_shape\n    glob: \"*.png\"\n    loop: true\n    fps: 20\n"
         "    trigger: free_run\n    colour: mono\n";
}

std::unique_ptr<ChildProcess> startFacetd(const TempDir& dir, const std::string& station,
                                          std::map<std::string, std::string> environment = {}) {
  return std::make_unique<ChildProcess>(
      std::vector<std::string>{FACETD_PATH, "--config", station, "--recipe", "2", "--no-plc",
                               "--log-level", "info"},
      std::move(environment), dir / "facetd.log");
}

// Part ids 1..N, each once: no taken part went missing, none was stored twice.
void expectContiguous(const std::vector<StoredPart>& parts) {
  for (std::size_t i = 0; i < parts.size(); ++i)
    ASSERT_EQ(parts[i].partId, static_cast<std::int64_t>(i) + 1) << "part ids have a hole";
}

void waitForParts(const std::string& database, std::size_t n, std::chrono::seconds timeout) {
  const auto until = Clock::now() + timeout;
  while (Clock::now() < until) {
    try {
      if (std::filesystem::exists(database) && storedParts(database).size() >= n) return;
    } catch (const std::exception&) {
      // facetd has created the file but not yet its tables
    }
    std::this_thread::sleep_for(100ms);
  }
  FAIL() << "fewer than " << n << " parts stored within " << timeout.count() << " s";
}

TEST(DaemonSystemd, NotifyProtocolAndCleanStop) {
  TempDir dir;
  const auto station = writeStationFile(dir.path(), replayCamera(), 0);
  NotifySocket notify(dir / "notify.sock");
  auto facetd =
      startFacetd(dir, station, {{"NOTIFY_SOCKET", notify.path()}, {"WATCHDOG_USEC", "1000000"}});
  ASSERT_TRUE(notify.waitFor("READY=1", 30s)) << "no READY=1\n" << facetd->outputTail();
  // WatchdogSec=1 s: pings at least every 0.5 s.
  const auto t0 = Clock::now();
  ASSERT_TRUE(notify.waitFor("WATCHDOG=1", 1500ms));
  ASSERT_TRUE(notify.waitFor("WATCHDOG=1", 1500ms));
  ASSERT_TRUE(notify.waitFor("WATCHDOG=1", 1500ms));
  EXPECT_LT(Clock::now() - t0, 3s);

  facetd->signal(SIGHUP);
  ASSERT_TRUE(notify.waitFor("RELOADING=1", 10s));
  ASSERT_TRUE(notify.waitFor("READY=1", 10s)) << "READY=1 must follow the reload";

  ASSERT_NO_FATAL_FAILURE(waitForParts(dir / "results.db", 5, 60s));
  facetd->signal(SIGTERM);
  ASSERT_TRUE(notify.waitFor("STOPPING=1", 10s));
  const auto code = facetd->wait(20s);
  ASSERT_TRUE(code.has_value()) << "facetd did not exit after SIGTERM";
  EXPECT_EQ(*code, 0);

  const auto parts = storedParts(dir / "results.db");
  ASSERT_GE(parts.size(), 5u);
  expectContiguous(parts);
  for (const auto& p : parts) EXPECT_EQ(p.recipeId, 2);
  EXPECT_EQ(integrityCheck(dir / "results.db"), "ok");
}

TEST(DaemonSystemd, WithoutWatchdogUsecNoPings) {
  TempDir dir;
  const auto station = writeStationFile(dir.path(), replayCamera(), 0);
  NotifySocket notify(dir / "notify.sock");
  auto facetd = startFacetd(dir, station, {{"NOTIFY_SOCKET", notify.path()}});
  ASSERT_TRUE(notify.waitFor("READY=1", 30s));
  EXPECT_FALSE(notify.waitFor("WATCHDOG=1", 1500ms)) << "pings without WatchdogSec";
  facetd->signal(SIGTERM);
  EXPECT_TRUE(notify.waitFor("STOPPING=1", 10s));
  EXPECT_EQ(facetd->wait(20s), std::optional<int>(0));
}

TEST(DaemonSystemd, KillThenRestartContinuesPartIds) {
  TempDir dir;
  const auto station = writeStationFile(dir.path(), replayCamera(), 0);
  const std::string database = dir / "results.db";
  {
    auto facetd = startFacetd(dir, station);
    ASSERT_NO_FATAL_FAILURE(waitForParts(database, 4, 60s));
    facetd->signal(SIGKILL);  // a power cut for the process: no flush, no goodbye
    EXPECT_EQ(facetd->wait(10s), std::optional<int>(128 + SIGKILL));
  }
  EXPECT_EQ(integrityCheck(database), "ok");
  // Killed mid-run: the parts in flight are lost (a missed part is published by acquisition
  // while an earlier one is still being inspected, so the stored ids may have a hole at the end).
  const auto before = storedParts(database);
  ASSERT_GE(before.size(), 4u);
  const std::int64_t lastBefore = before.back().partId;

  auto facetd = startFacetd(dir, station);
  ASSERT_NO_FATAL_FAILURE(waitForParts(database, before.size() + 3, 60s));
  facetd->signal(SIGTERM);
  EXPECT_EQ(facetd->wait(20s), std::optional<int>(0));
  const auto after = storedParts(database);
  EXPECT_EQ(integrityCheck(database), "ok");
  ASSERT_GT(after.size(), before.size());
  for (std::size_t i = 0; i < before.size(); ++i) {  // the old rows are untouched
    EXPECT_EQ(after[i].partId, before[i].partId);
    EXPECT_EQ(after[i].verdict, before[i].verdict);
    EXPECT_EQ(after[i].frameId, before[i].frameId);
  }
  // The restarted daemon continues after the last stored id, and (stopped cleanly) stores every
  // part it took.
  for (std::size_t i = before.size(); i < after.size(); ++i)
    EXPECT_EQ(after[i].partId, lastBefore + static_cast<std::int64_t>(i - before.size()) + 1);
}

}  // namespace
}  // namespace facet::daemon_test
