#pragma once
// Runs the built `facet` tool the way a user does, for the command-line tests: its stdout, its
// stderr and its exit code. The including test target defines FACET_CLI (the binary's path).

#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

namespace facet::test {

struct CliRun {
  int exitCode = -1;  // -1 when the tool could not be started or did not exit normally
  std::string out;
  std::string err;
};

// `args` is appended to the binary's path on a shell command line (quote paths with spaces).
inline CliRun runFacet(const std::string& args) {
  namespace fs = std::filesystem;
  static int calls = 0;
  const fs::path errFile =
      fs::temp_directory_path() /
      ("facet_cli_err_" + std::to_string(::getpid()) + "_" + std::to_string(++calls) + ".txt");
  const std::string command = std::string(FACET_CLI) + " " + args + " 2>" + errFile.string();
  CliRun run;
  FILE* pipe = ::popen(command.c_str(), "r");
  if (pipe == nullptr) return run;
  char buffer[4096];
  while (const std::size_t n = std::fread(buffer, 1, sizeof buffer, pipe))
    run.out.append(buffer, n);
  const int status = ::pclose(pipe);
  run.exitCode = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  std::ifstream in(errFile);
  run.err.assign(std::istreambuf_iterator<char>(in), {});
  fs::remove(errFile);
  return run;
}

}  // namespace facet::test
