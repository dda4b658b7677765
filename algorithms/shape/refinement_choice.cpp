#include "algorithms/shape/refinement_choice.hpp"

namespace facet::shape_detail {

bool keepsRefinedPose(const RefinementOutcome& o, double minScore) {
  if (!o.fittedFully) return o.refinedScore >= o.startScore;
  if (o.refinedScore < minScore && o.startScore >= minScore) return false;
  if (o.refinedScore < o.startScore - kMaxRefinementScoreLoss) return false;
  return o.refinedSupport >= o.startSupport;
}

}  // namespace facet::shape_detail
