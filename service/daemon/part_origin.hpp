#pragma once
// Where a part came from, as every publisher records it: the recipe that inspected it (id, name,
// content hash), the frame (id, source) and the frame's sidecar (serial, expected verdict).
// Shared by facetd's station and `facet replay` so that both store a part the same way.

#include "camera/camera.hpp"
#include "config/recipe.hpp"
#include "service/engine/part_result.hpp"

namespace facet::service {

// Fills the origin fields of `part`; `recipe` may be null (no recipe could be chosen).
void recordPartOrigin(PartResult& part, const config::Recipe* recipe, const Frame& frame);

}  // namespace facet::service
