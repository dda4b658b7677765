#include "tests/daemon/child_process.hpp"

#include <fcntl.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <deque>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace facet::daemon_test {

ChildProcess::ChildProcess(std::vector<std::string> argv,
                           std::map<std::string, std::string> environment, std::string stderrFile)
    : stderrFile_(stderrFile) {
  // Everything the child needs is built before fork: the test's reader threads may hold the
  // allocator's lock at the fork, and a child that allocates before exec then hangs for ever.
  std::vector<char*> args;
  for (auto& a : argv) args.push_back(a.data());
  args.push_back(nullptr);
  std::vector<std::string> envStrings;
  for (char** e = environ; *e != nullptr; ++e) {
    const std::string entry = *e;
    if (!environment.count(entry.substr(0, entry.find('=')))) envStrings.push_back(entry);
  }
  for (const auto& [key, value] : environment) envStrings.push_back(key + "=" + value);
  std::vector<char*> envp;
  for (auto& e : envStrings) envp.push_back(e.data());
  envp.push_back(nullptr);
  const int errFd = stderrFile.empty() ? -1
                                       : ::open(stderrFile.c_str(),
                                                O_WRONLY | O_CREAT | O_APPEND | O_CLOEXEC, 0644);
  int out[2];
  if (::pipe2(out, O_CLOEXEC) != 0) throw std::runtime_error("pipe failed");
  ::signal(SIGPIPE, SIG_IGN);
  sigset_t none;
  sigemptyset(&none);
  pid_ = ::fork();
  if (pid_ < 0) throw std::runtime_error("fork failed");
  if (pid_ == 0) {
    // Only async-signal-safe calls from here to exec.
    ::prctl(PR_SET_PDEATHSIG, SIGKILL);  // a crashed test leaves no camera or daemon behind
    ::dup2(out[1], STDOUT_FILENO);
    if (errFd >= 0) ::dup2(errFd, STDERR_FILENO);
    // The test's blocked signals must not stay blocked in the child.
    ::sigprocmask(SIG_SETMASK, &none, nullptr);
    ::execve(args[0], args.data(), envp.data());
    static const char kFailed[] = "exec of the child process failed\n";
    [[maybe_unused]] const auto written = ::write(STDERR_FILENO, kFailed, sizeof kFailed - 1);
    ::_exit(127);
  }
  if (errFd >= 0) ::close(errFd);
  ::close(out[1]);
  reader_ = std::thread([this, fd = out[0]] { readLoop(fd); });
}

ChildProcess::~ChildProcess() {
  if (!exitCode_) {
    ::kill(pid_, SIGKILL);
    wait(std::chrono::seconds(10));
  }
  if (reader_.joinable()) reader_.join();
}

void ChildProcess::signal(int sig) const {
  if (!exitCode_) ::kill(pid_, sig);
}

std::optional<int> ChildProcess::wait(std::chrono::milliseconds timeout) {
  if (exitCode_) return exitCode_;
  const auto until = std::chrono::steady_clock::now() + timeout;
  while (true) {
    int status = 0;
    const pid_t r = ::waitpid(pid_, &status, WNOHANG);
    if (r == pid_) {
      exitCode_ = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
      // The reader thread may not have taken the last lines from the pipe yet: lines() right
      // after wait() must see everything the child printed. A grandchild that keeps the pipe
      // open must not hold the test for long, hence the bound.
      std::unique_lock lock(mutex_);
      changed_.wait_until(
          lock, std::min(until, std::chrono::steady_clock::now() + std::chrono::seconds(5)),
          [this] { return eof_; });
      return exitCode_;
    }
    if (std::chrono::steady_clock::now() > until) return std::nullopt;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
}

std::optional<std::string> ChildProcess::waitForLine(
    const std::function<bool(const std::string&)>& match, std::chrono::milliseconds timeout) {
  std::unique_lock lock(mutex_);
  std::size_t checked = 0;
  const auto until = std::chrono::steady_clock::now() + timeout;
  while (true) {
    for (; checked < lines_.size(); ++checked)
      if (match(lines_[checked])) return lines_[checked];
    if (eof_) return std::nullopt;
    if (changed_.wait_until(lock, until) == std::cv_status::timeout) {
      for (; checked < lines_.size(); ++checked)
        if (match(lines_[checked])) return lines_[checked];
      return std::nullopt;
    }
  }
}

std::vector<std::string> ChildProcess::lines() const {
  std::lock_guard lock(mutex_);
  return lines_;
}

void ChildProcess::readLoop(int fd) {
  std::string pending;
  char buf[4096];
  while (true) {
    const ssize_t n = ::read(fd, buf, sizeof buf);
    if (n <= 0) break;
    pending.append(buf, static_cast<std::size_t>(n));
    std::size_t end;
    while ((end = pending.find('\n')) != std::string::npos) {
      std::lock_guard lock(mutex_);
      lines_.push_back(pending.substr(0, end));
      pending.erase(0, end + 1);
      changed_.notify_all();
    }
  }
  ::close(fd);
  std::lock_guard lock(mutex_);
  eof_ = true;
  changed_.notify_all();
}

TempDir::TempDir() {
  char name[] = "/tmp/facet-daemon-test-XXXXXX";
  if (!::mkdtemp(name)) throw std::runtime_error("mkdtemp failed");
  path_ = name;
}

TempDir::~TempDir() {
  std::error_code ignored;
  if (!std::getenv("FACET_KEEP_TEST_DIRS")) std::filesystem::remove_all(path_, ignored);
}

std::string ChildProcess::outputTail(std::size_t count) const {
  std::ostringstream out;
  const auto all = lines();
  out << "--- last " << std::min(count, all.size()) << " of " << all.size()
      << " lines of stdout ---\n";
  for (std::size_t i = all.size() - std::min(count, all.size()); i < all.size(); ++i)
    out << all[i] << "\n";
  if (!stderrFile_.empty()) {
    std::deque<std::string> last;
    std::ifstream in(stderrFile_);
    for (std::string l; std::getline(in, l);) {
      last.push_back(l);
      if (last.size() > count) last.pop_front();
    }
    out << "--- last " << last.size() << " lines of stderr (" << stderrFile_ << ") ---\n";
    for (const auto& l : last) out << l << "\n";
  }
  return out.str();
}

}  // namespace facet::daemon_test
