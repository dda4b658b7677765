// facetd with facet's step kinds (see facetd_main.cpp).
#include "service/daemon/exit_leak_check.hpp"
#include "service/daemon/facetd_main.hpp"
#include "service/engine/builtin_steps.hpp"

int main(int argc, char** argv) {
  int exitCode = 0;
  {
    const auto kinds = facet::service::builtinSteps();
    exitCode = facet::service::runFacetd(argc, argv, kinds);
  }
  return facet::service::checkLeaksNow(exitCode);
}
