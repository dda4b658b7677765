// facetd with facet's step kinds (see facetd_main.cpp).
#include "service/daemon/facetd_main.hpp"
#include "service/engine/builtin_steps.hpp"

int main(int argc, char** argv) {
  const auto kinds = facet::service::builtinSteps();
  return facet::service::runFacetd(argc, argv, kinds);
}
