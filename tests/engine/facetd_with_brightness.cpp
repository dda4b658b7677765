// `facetd` with the test-only brightness step kind registered beside facet's own.
#include "service/daemon/facetd_main.hpp"
#include "tests/engine/brightness_step.hpp"

int main(int argc, char** argv) {
  const auto kinds = facet::test::stepsWithBrightness();
  return facet::service::runFacetd(argc, argv, kinds);
}
