#include "service/daemon/part_origin.hpp"

namespace facet::service {

void recordPartOrigin(PartResult& part, const config::Recipe* recipe, const Frame& frame) {
  if (recipe) {
    part.recipeId = recipe->id;
    part.recipeName = recipe->name;
    part.recipeVersion = recipe->contentHash;
  }
  part.frameId = frame.id;
  part.source = frame.source;
  if (auto it = frame.metadata.find("serial"); it != frame.metadata.end()) part.serial = it->second;
  if (auto it = frame.metadata.find("expected_verdict"); it != frame.metadata.end())
    part.expectedVerdict = it->second;
  if (auto it = frame.metadata.find("defect"); it != frame.metadata.end())
    part.recordedDefect = it->second;
}

}  // namespace facet::service
