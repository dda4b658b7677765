// The similarity of a pose with a deformation tolerance against its definition: each model point
// inside the image adds its best normalised dot product with the image directions within
// `spread` pixels in x and y, or 0 where that is lower; the mean over the model's points. The
// search reads a window row as one vector where it lies 8 pixels inside the image, pixel by pixel
// elsewhere; neither may change a value.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "algorithms/shape/image_gradients.hpp"
#include "algorithms/shape/shape_model.hpp"
#include "algorithms/shape/shape_similarity.hpp"
#include "tests/shape/bracket_scenes.hpp"

namespace facet {
namespace {

using shape_detail::Direction;

double definedScore(const cv::Mat& field, const shape_detail::PosedPoints& posed, cv::Point at,
                    bool local, int spread) {
  double sum = 0.0;
  for (std::size_t j = 0; j < posed.offsets.size(); ++j) {
    const int x = at.x + posed.offsets[j].x, y = at.y + posed.offsets[j].y;
    if (x < 0 || y < 0 || x >= field.cols || y >= field.rows) continue;
    const int mx = static_cast<int>(std::lround(posed.directions[j].x * 128.0f));
    const int my = static_cast<int>(std::lround(posed.directions[j].y * 128.0f));
    int best = 0;
    for (int v = std::max(y - spread, 0); v <= std::min(y + spread, field.rows - 1); ++v)
      for (int u = std::max(x - spread, 0); u <= std::min(x + spread, field.cols - 1); ++u) {
        const Direction d = field.at<Direction>(v, u);
        const int dot = d[0] * mx + d[1] * my;
        best = std::max(best, local ? std::abs(dot) : dot);
      }
    sum += best / (127.0 * 128.0);
  }
  return sum / static_cast<double>(posed.offsets.size());
}

TEST(SpreadSimilarity, ScoresAreTheDefinitionInsideAndAtTheImagesBorders) {
  const ShapeModel model = createShapeModel(testing::bracketTemplate());
  const cv::Mat scene = testing::bracketScene({320, 240}, {{150.3, 118.6, 0.7, 1.0}}, 3);
  shape_detail::DirectionField directions(scene, model.minContrast);
  directions.ensureAll();
  const cv::Mat& field = directions.directions();
  const auto posed = shape_detail::posePoints(model.levels[0].points, 0.7, 1.0);
  int compared = 0;
  for (const Polarity polarity : {Polarity::Use, Polarity::IgnoreLocal})
    for (int spread = 1; spread <= 3; ++spread)
      // Around the part, and with it cut by each of the image's borders.
      for (const cv::Point at :
           {cv::Point(150, 119), cv::Point(153, 116), cv::Point(4, 119), cv::Point(316, 119),
            cv::Point(150, 3), cv::Point(150, 237), cv::Point(0, 0), cv::Point(319, 239)}) {
        const bool local = polarity == Polarity::IgnoreLocal;
        const double expected = definedScore(field, posed, at, local, spread);
        EXPECT_NEAR(shape_detail::scorePose(field, posed, at, polarity, 0.0, 0.0, spread), expected,
                    1e-12)
            << "spread " << spread << " at " << at << (local ? " local" : "");
        ++compared;
      }
  EXPECT_EQ(compared, 48);
  // On the part a tolerance can only raise the score; a pose 2 px off, lower rigidly, scores about
  // as the exact one with a tolerance of 2.
  const cv::Point part(150, 119);
  const double rigid = shape_detail::scorePose(field, posed, part, Polarity::Use, 0.0, 0.0, 0);
  EXPECT_GE(shape_detail::scorePose(field, posed, part, Polarity::Use, 0.0, 0.0, 1), rigid);
  EXPECT_LT(
      shape_detail::scorePose(field, posed, part + cv::Point(2, 0), Polarity::Use, 0.0, 0.0, 0),
      rigid - 0.03);
  EXPECT_GE(
      shape_detail::scorePose(field, posed, part + cv::Point(2, 0), Polarity::Use, 0.0, 0.0, 2),
      rigid - 0.02);
}

}  // namespace
}  // namespace facet
