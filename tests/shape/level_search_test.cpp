// The local search that tracks a candidate down the pyramid against its definition: the first pose
// of the best score in its neighbourhood, climbing while that lies on the border. The search
// abandons poses early against the best so far and against the centre's own score; neither may
// change the pose it keeps, on a rigid or a deformation-tolerant score.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "algorithms/shape/image_gradients.hpp"
#include "algorithms/shape/level_search.hpp"
#include "algorithms/shape/shape_model.hpp"
#include "algorithms/shape/shape_similarity.hpp"
#include "tests/shape/bracket_scenes.hpp"

namespace facet {
namespace {

using shape_detail::Candidate;
using shape_detail::LevelSearch;

// refineOnLevel as defined: every pose scored in full (no early termination), the first of the
// best kept; the neighbourhood of the best searched again while it lies on the border.
Candidate exhaustiveRefine(const LevelSearch& s, Candidate c, int radius, int angleSteps) {
  const double aStep = s.level->angleStep;
  Candidate best = c;
  best.score = -1.0;
  for (int climb = 0; climb < 6; ++climb) {
    const Candidate centre = climb == 0 ? c : best;
    bool onBorder = false;
    for (int k = -angleSteps; k <= angleSteps; ++k) {
      const double a = shape_detail::clampAngle(s.angles, centre.angle + k * aStep);
      const shape_detail::PosedPoints posed = shape_detail::posePoints(s.level->points, a, 1.0);
      for (int dy = -radius; dy <= radius; ++dy)
        for (int dx = -radius; dx <= radius; ++dx) {
          const cv::Point at(cvRound(centre.x) + dx, cvRound(centre.y) + dy);
          double score =
              shape_detail::scorePose(*s.field, posed, at, s.polarity, 0.0, 0.0, s.spread);
          if (score > best.score) {
            best = {double(at.x), double(at.y), a, 1.0, score};
            onBorder = std::abs(dx) == radius || std::abs(dy) == radius ||
                       (std::abs(k) == angleSteps && aStep > 0.0);
          }
        }
    }
    if (!onBorder || best.score < s.minScore) break;
    radius = 1;
    angleSteps = 1;
  }
  return best;
}

class LevelSearchTest : public ::testing::TestWithParam<int> {};

TEST_P(LevelSearchTest, KeepsThePoseAnExhaustiveSearchKeeps) {
  const int spread = GetParam();
  const ShapeModel model = createShapeModel(testing::bracketTemplate());
  const Pose2D truth{203.4, 171.7, 0.61, 1.0};
  const cv::Mat image = testing::bracketScene({420, 360}, {truth}, 31);
  shape_detail::DirectionField field(image, model.minContrast);
  field.ensureAll();

  LevelSearch s;
  s.field = &field.directions();
  s.level = &model.levels[0];
  s.angles = {0.0, 2.0 * CV_PI, true};
  s.spread = spread;
  int kept = 0;
  // Starts around the part (where tracking starts) and away from it (where most poses fail),
  // at thresholds below, near and above the part's score.
  for (const double minScore : {0.3, 0.56, 0.9, 0.97}) {
    s.minScore = minScore;
    for (int dy = -4; dy <= 4; dy += 2)
      for (int dx = -4; dx <= 4; dx += 2)
        for (int k = -2; k <= 2; ++k) {
          const Candidate start{std::round(truth.x) + dx, std::round(truth.y) + dy,
                                truth.angle + k * s.level->angleStep, 1.0, 0.0};
          for (const int radius : {1, 2}) {
            const Candidate fast = shape_detail::refineOnLevel(s, start, radius);
            const Candidate slow = exhaustiveRefine(s, start, radius, 1);
            // Below the threshold the search may stop anywhere: the candidate fails either way.
            if (slow.score < minScore) {
              EXPECT_LT(fast.score, minScore);
              continue;
            }
            ASSERT_EQ(fast.score, slow.score) << "start " << dx << "," << dy << "," << k;
            EXPECT_EQ(fast.x, slow.x);
            EXPECT_EQ(fast.y, slow.y);
            EXPECT_EQ(fast.angle, slow.angle);
            ++kept;
          }
        }
  }
  // The comparisons covered poses that were kept, not only ones that failed everywhere.
  EXPECT_GT(kept, 200);
}

INSTANTIATE_TEST_SUITE_P(RigidAndTolerant, LevelSearchTest, ::testing::Values(0, 1),
                         [](const auto& info) { return info.param ? "Spread1" : "Rigid"; });

}  // namespace
}  // namespace facet
