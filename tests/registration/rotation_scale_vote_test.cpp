// agreeingRotationScale on matches with known rotations and scales.
#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "algorithms/registration/rotation_scale_vote.hpp"

namespace facet {
namespace {

FeatureMatch withRotationScale(double deg, double scale) {
  FeatureMatch m;
  m.rotationDeg = deg;
  m.scale = scale;
  return m;
}

// 30 true matches of a view magnified 2.5 times and turned 30 degrees (each a little off, as a
// window's shifts give them), among 400 chance matches of every rotation and of scales about 1,
// as where the image shows a small part of the reference.
TEST(AgreeingRotationScale, AFewMatchesOfAStrongZoomStandOutAmongManyChanceOnes) {
  std::mt19937 rng(9);
  std::uniform_real_distribution<double> anyTurn(-180, 180), jitter(-4, 4);
  std::normal_distribution<double> chanceLog2Scale(0.0, 0.5), trueLog2Jitter(0.0, 0.1);
  std::vector<FeatureMatch> matches;
  for (int i = 0; i < 30; ++i)
    matches.push_back(
        withRotationScale(30 + jitter(rng), std::exp2(std::log2(2.5) + trueLog2Jitter(rng))));
  for (int i = 0; i < 400; ++i)
    matches.push_back(withRotationScale(anyTurn(rng), std::exp2(chanceLog2Scale(rng))));
  const std::vector<int> kept = agreeingRotationScale(matches, 40.0, 1.0);
  for (int i = 0; i < 30; ++i)
    EXPECT_TRUE(std::count(kept.begin(), kept.end(), i)) << "true match " << i << " pruned";
  // Chance matches kept: those that happen to lie near the true rotation and scale.
  EXPECT_LT(kept.size(), 30u + 60u);
}

TEST(AgreeingRotationScale, RotationsWrapAroundAndNothingIsPrunedWhenOff) {
  std::vector<FeatureMatch> matches;
  for (int i = 0; i < 10; ++i) matches.push_back(withRotationScale(i % 2 ? 178.0 : -178.0, 1.0));
  matches.push_back(withRotationScale(0.0, 1.0));
  const std::vector<int> kept = agreeingRotationScale(matches, 40.0, 1.0);
  EXPECT_EQ(kept.size(), 10u);
  EXPECT_EQ(std::count(kept.begin(), kept.end(), 10), 0);
  EXPECT_EQ(agreeingRotationScale(matches, 0.0, 1.0).size(), matches.size());
}

}  // namespace
}  // namespace facet
