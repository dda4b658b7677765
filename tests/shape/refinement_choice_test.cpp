// Which pose a match keeps, the interpolated start or its least-squares refinement. The cases are
// the ones met on real parts: a hole out of place (the refinement fits the rest of the part and
// scores a little lower), and a small shiny part whose texture the refinement locked onto (it
// laid more points on edges and lost a third of the score).
#include <gtest/gtest.h>

#include "algorithms/shape/refinement_choice.hpp"

namespace facet::shape_detail {
namespace {

RefinementOutcome outcome(double startScore, double refinedScore, double startSupport,
                          double refinedSupport, bool fittedFully = true, bool exactFit = false) {
  return {startScore, refinedScore, startSupport, refinedSupport, fittedFully, exactFit};
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

TEST(RefinementChoice, AnExactFitMayLoseMoreScoreThanADisplacedFeatureHolds) {
  // A 40% occluded part: the rough start, 1.6 px off beside the occluder, scores 0.683; the
  // refinement lays 162 points on the visible part's edges (a median 0.02 px off) at 0.583.
  EXPECT_TRUE(keepsRefinedPose(outcome(0.683, 0.583, 67.0, 162.3, true, true)));
  EXPECT_FALSE(keepsRefinedPose(outcome(0.683, 0.583, 67.0, 162.3, true, false)))
      << "the same figures from a loose fit (texture, a neighbour's edges) are refused";
  EXPECT_FALSE(keepsRefinedPose(outcome(0.683, 0.583, 162.3, 67.0, true, true)))
      << "fewer points on edges: the start is kept";
  EXPECT_FALSE(keepsRefinedPose(outcome(0.683, 0.583, 67.0, 162.3, false, true)))
      << "a part held at a scale it does not have is judged by the score";
}

TEST(RefinementChoice, AStartAHairFromTheFitDoesNotOutweighIt) {
  // An exact part: the start 0.017 px off the fit's pose lays 592.3 of 600 points on edges, the
  // fit 591.3; the fit is kept wherever it started. A tenth more (a displaced hole) is not a hair.
  EXPECT_TRUE(keepsRefinedPose(outcome(0.9999, 0.9999, 592.270, 591.342, true, true)));
  EXPECT_TRUE(keepsRefinedPose(outcome(0.9999, 0.9999, 592.270, 591.342)));
  EXPECT_FALSE(keepsRefinedPose(outcome(0.9999, 0.9999, 592.270, 592.270 * 0.985, true, true)));
}

TEST(RefinementChoice, APartHeldAtAScaleItDoesNotHaveIsJudgedByTheScore) {
  EXPECT_TRUE(keepsRefinedPose(outcome(0.90, 0.91, 300.0, 200.0, false)));
  EXPECT_FALSE(keepsRefinedPose(outcome(0.91, 0.90, 200.0, 300.0, false)));
}

}  // namespace
}  // namespace facet::shape_detail
