// facet with facet's step kinds (see main.cpp).
#include "service/cli/command_line.hpp"
#include "service/daemon/exit_leak_check.hpp"
#include "service/engine/builtin_steps.hpp"

int main(int argc, char** argv) {
  int exitCode = 0;
  {
    const auto kinds = facet::service::builtinSteps();
    exitCode = facet::cli::runFacet(argc, argv, kinds);
  }
  return facet::service::checkLeaksNow(exitCode);
}
