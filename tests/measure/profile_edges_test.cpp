// The profile edge estimator on profiles computed exactly: shading across an edge whose window
// is cut short, and the noise of the position against the Cramer-Rao bound.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>

#include "algorithms/measure/profile_edges.hpp"

namespace facet {
namespace {

// A step of `height` blurred by a Gaussian of `blur` px at `edge`, on a background `level` that
// rises by `shading` grey levels per px, sampled every `step` px over [start, start + length].
GreyProfile shadedStep(double start, double length, double step, double edge, double level,
                       double height, double blur, double shading) {
  GreyProfile p;
  p.start = start;
  p.step = step;
  for (double s = start; s <= start + length + 1e-9; s += step)
    p.values.push_back(level + shading * (s - start) +
                       height * 0.5 * std::erfc(-(s - edge) / (blur * std::sqrt(2.0))));
  return p;
}

TEST(ProfileEdges, ShadingDoesNotMoveAnEdgeWhoseWindowIsCutShort) {
  // Edges 2.5-4 px from either end of a 40 px profile: their windows reach far into the profile
  // on one side only, where a flat-level model would read the shading as a shift.
  double worst = 0;
  for (double shading : {-1.5, -0.4, 0.4, 1.5})
    for (double fromEnd : {2.5, 3.1, 4.0})
      for (bool nearStart : {true, false}) {
        const double edge = nearStart ? fromEnd : 40.0 - fromEnd;
        const GreyProfile p = shadedStep(0, 40, 0.25, edge, 60, 110, 1.0, shading);
        const std::vector<ProfileEdge> found = findProfileEdges(p);
        ASSERT_EQ(found.size(), 1u) << shading << " " << edge;
        worst = std::max(worst, std::abs(found[0].position - edge));
      }
  EXPECT_LT(worst, 0.002);
}

TEST(ProfileEdges, AFaintStepBesideAnEdgeDoesNotMoveIt) {
  // Steps below the minimum amplitude 5-7 px from an edge (a chamfer, a scratch): not edges, but
  // inside its window they would pull its levels. Fainter than half the minimum they stop the
  // window; stronger, they are fitted and subtracted like a neighbour.
  for (double faint : {8.0, 12.0, 16.0, 19.0})
    for (double away : {-7.0, -5.0, 5.0, 7.0}) {
      GreyProfile p = shadedStep(0, 40, 0.25, 20.3, 60, 100, 1.0, 0.0);
      for (std::size_t i = 0; i < p.values.size(); ++i)
        p.values[i] += faint * 0.5 * std::erfc(-(p.positionAt(i) - 20.3 - away) / std::sqrt(2.0));
      const std::vector<ProfileEdge> found = findProfileEdges(p);
      ASSERT_EQ(found.size(), 1u) << faint << " at " << away;
      // 5 px away its blur still reaches the 4 px either side every fit uses: 0.006 px.
      EXPECT_NEAR(found[0].position, 20.3, std::abs(away) < 6 ? 0.01 : 0.001)
          << faint << " at " << away;
    }
}

TEST(ProfileEdgesStatistics, PositionNoiseIsNearTheCramerRaoBound) {
  // Pixel-spaced samples with independent noise: the bound for the position alone, the levels
  // and blur known, is noise / (height sqrt(1 / (2 sqrt(pi) blur))). Estimating the levels from
  // a few pixels beside the edge costs far more than that; from the whole window, little.
  const double noise = 2.0, height = 100.0, blur = 1.0;
  const double bound = noise / (height * std::sqrt(1.0 / (2.0 * std::sqrt(M_PI) * blur)));
  std::mt19937_64 rng(11);
  std::normal_distribution<double> n(0.0, noise);
  std::uniform_real_distribution<double> u(-0.5, 0.5);
  double sum = 0;
  const int trials = 600;
  for (int k = 0; k < trials; ++k) {
    const double edge = 20.0 + u(rng);
    GreyProfile p = shadedStep(0, 40, 1.0, edge, 70, height, blur, 0.0);
    for (double& v : p.values) v += n(rng);
    const std::vector<ProfileEdge> found = findProfileEdges(p);
    ASSERT_EQ(found.size(), 1u) << k;
    sum += (found[0].position - edge) * (found[0].position - edge);
  }
  const double rms = std::sqrt(sum / trials);
  std::printf("position RMS %.4f px, bound %.4f px, ratio %.3f\n", rms, bound, rms / bound);
  EXPECT_LT(rms, 1.2 * bound);
}

}  // namespace
}  // namespace facet
