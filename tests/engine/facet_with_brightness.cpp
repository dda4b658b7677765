// `facet` with the test-only brightness step kind registered beside facet's own.
#include "service/cli/command_line.hpp"
#include "tests/engine/brightness_step.hpp"

int main(int argc, char** argv) {
  const auto kinds = facet::test::stepsWithBrightness();
  return facet::cli::runFacet(argc, argv, kinds);
}
