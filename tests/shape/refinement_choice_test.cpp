// Which pose a match keeps, the interpolated start or its least-squares refinement. The cases are
// the ones met on real parts: a hole out of place (the refinement fits the rest of the part and
// scores a little lower), and a small shiny part whose texture the refinement locked onto (it
// laid more points on edges and lost a third of the score).
#include <gtest/gtest.h>

#include "algorithms/shape/refinement_choice.hpp"

namespace facet::shape_detail {
namespace {

RefinementOutcome outcome(double startScore, double refinedScore, double startSupport,
                          double refinedSupport, bool fittedFully = true) {
  return {startScore, refinedScore, startSupport, refinedSupport, fittedFully};
}

TEST(RefinementChoice, AFullFitIsJudgedByItsSupportWhenTheScoresAreClose) {
  // A displaced hole: the tilted start scores 0.909, the refinement fits the rest at 0.906.
  EXPECT_TRUE(keepsRefinedPose(outcome(0.909, 0.906, 290.0, 320.0), 0.7));
  EXPECT_FALSE(keepsRefinedPose(outcome(0.909, 0.912, 320.0, 290.0), 0.7))
      << "fewer points on edges: the start is kept even though the refinement scores higher";
}

TEST(RefinementChoice, ARefinementThatLosesMoreThanADisplacedFeatureHoldsIsRefused) {
  // Seen on a photograph of LEDs: 0.94 -> 0.50 with 51 instead of 20 points on edges.
  const RefinementOutcome o = outcome(0.94, 0.50, 20.0, 51.0);
  EXPECT_FALSE(keepsRefinedPose(o, 0.7));
  // The minimum score only filters matches; the pose kept must not depend on it (it did: at
  // 0.5 the refinement's 0.50 was returned, at 0.7 the start's 0.94).
  for (double minScore : {0.3, 0.5, 0.55, 0.7, 0.9}) EXPECT_FALSE(keepsRefinedPose(o, minScore));
  EXPECT_TRUE(
      keepsRefinedPose(outcome(0.94, 0.94 - 0.9 * kMaxRefinementScoreLoss, 20.0, 51.0), 0.5));
}

TEST(RefinementChoice, ARefinementNeverTurnsAPartFoundIntoOneMissed) {
  EXPECT_FALSE(keepsRefinedPose(outcome(0.72, 0.68, 100.0, 150.0), 0.7));
  EXPECT_TRUE(keepsRefinedPose(outcome(0.72, 0.68, 100.0, 150.0), 0.6));
}

TEST(RefinementChoice, APartHeldAtAScaleItDoesNotHaveIsJudgedByTheScore) {
  EXPECT_TRUE(keepsRefinedPose(outcome(0.90, 0.91, 300.0, 200.0, false), 0.7));
  EXPECT_FALSE(keepsRefinedPose(outcome(0.91, 0.90, 200.0, 300.0, false), 0.7));
}

}  // namespace
}  // namespace facet::shape_detail
