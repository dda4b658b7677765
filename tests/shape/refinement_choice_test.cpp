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
  EXPECT_TRUE(keepsRefinedPose(outcome(0.909, 0.906, 290.0, 320.0)));
  EXPECT_FALSE(keepsRefinedPose(outcome(0.909, 0.912, 320.0, 290.0)))
      << "fewer points on edges: the start is kept even though the refinement scores higher";
}

TEST(RefinementChoice, ARefinementThatLosesMoreThanADisplacedFeatureHoldsIsRefused) {
  // Seen on a photograph of LEDs: 0.94 -> 0.50 with 51 instead of 20 points on edges.
  const RefinementOutcome o = outcome(0.94, 0.50, 20.0, 51.0);
  EXPECT_FALSE(keepsRefinedPose(o));
  EXPECT_TRUE(keepsRefinedPose(outcome(0.94, 0.94 - 0.9 * kMaxRefinementScoreLoss, 20.0, 51.0)));
}

TEST(RefinementChoice, AKeptRefinementNeverTurnsAPartFoundIntoOneMissed) {
  // A 40% occluded part: the refinement lands on the true pose and lays far more points on
  // edges, while its similarity falls a little below a minimum the start met.
  const RefinementOutcome o = outcome(0.5033, 0.4875, 117.8, 186.3);
  EXPECT_TRUE(keepsRefinedPose(o));
  EXPECT_DOUBLE_EQ(keptRefinementScore(o), 0.5033);
  EXPECT_DOUBLE_EQ(keptRefinementScore(outcome(0.80, 0.83, 100.0, 120.0)), 0.83);
}

TEST(RefinementChoice, APartHeldAtAScaleItDoesNotHaveIsJudgedByTheScore) {
  EXPECT_TRUE(keepsRefinedPose(outcome(0.90, 0.91, 300.0, 200.0, false)));
  EXPECT_FALSE(keepsRefinedPose(outcome(0.91, 0.90, 200.0, 300.0, false)));
}

}  // namespace
}  // namespace facet::shape_detail
