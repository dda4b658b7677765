#include "algorithms/shape/refinement_choice.hpp"

#include <algorithm>

namespace facet::shape_detail {

bool keepsRefinedPose(const RefinementOutcome& o) {
  if (!o.fittedFully) return o.refinedScore >= o.startScore;
  if (!o.exactFit && o.refinedScore < o.startScore - kMaxRefinementScoreLoss) return false;
  return o.refinedSupport >= o.startSupport * (1.0 - kSupportTolerance);
}

double keptRefinementScore(const RefinementOutcome& o) {
  return std::max(o.startScore, o.refinedScore);
}

}  // namespace facet::shape_detail
