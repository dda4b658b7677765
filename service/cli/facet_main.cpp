// facet with facet's step kinds (see main.cpp).
#include "service/cli/command_line.hpp"
#include "service/engine/builtin_steps.hpp"

int main(int argc, char** argv) {
  const auto kinds = facet::service::builtinSteps();
  return facet::cli::runFacet(argc, argv, kinds);
}
