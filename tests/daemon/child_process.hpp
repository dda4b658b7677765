#pragma once
// ChildProcess: a program of the build (facetd, fake_gige_camera) run as a child of the test,
// with its stdout read line by line on a thread so the test can wait for what it prints.

#include <sys/types.h>

#include <chrono>
#include <condition_variable>
#include <functional>
#include <map>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

namespace facet::daemon_test {

class ChildProcess {
 public:
  // Starts `argv[0]` with the given arguments; `environment` entries are added to (or replace
  // those of) the test's own. stderr goes to `stderrFile` when given, else to the test's stderr.
  ChildProcess(std::vector<std::string> argv, std::map<std::string, std::string> environment = {},
               std::string stderrFile = {});
  ~ChildProcess();  // SIGKILL if still running
  ChildProcess(const ChildProcess&) = delete;
  ChildProcess& operator=(const ChildProcess&) = delete;

  pid_t pid() const { return pid_; }
  void signal(int sig) const;
  // Waits for the exit; returns the exit code (128 + signal when killed), nullopt on timeout.
  std::optional<int> wait(std::chrono::milliseconds timeout);
  // Waits until a line of stdout satisfies `match`; returns it, or nullopt on timeout / exit.
  std::optional<std::string> waitForLine(const std::function<bool(const std::string&)>& match,
                                         std::chrono::milliseconds timeout);
  std::vector<std::string> lines() const;
  // The last `count` lines of stdout and of the stderr file, for a failure message: the test's
  // temporary folder (and the file with it) is gone once the test has failed.
  std::string outputTail(std::size_t count = 40) const;

 private:
  void readLoop(int fd);

  pid_t pid_ = -1;
  std::string stderrFile_;
  std::optional<int> exitCode_;
  std::thread reader_;
  mutable std::mutex mutex_;
  std::condition_variable changed_;
  std::vector<std::string> lines_;
  bool eof_ = false;
};

// A fresh directory under /tmp, removed with everything in it at the end of the scope.
class TempDir {
 public:
  TempDir();
  ~TempDir();
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  const std::string& path() const { return path_; }
  std::string operator/(const std::string& name) const { return path_ + "/" + name; }

 private:
  std::string path_;
};

}  // namespace facet::daemon_test
