// The least-squares refinement's shared edge detection: the refinements from a part's alternative
// poses run on one detection over the union of their regions, and must reach what each reaches on
// a detection of its own region.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <vector>

#include "algorithms/shape/least_squares_refinement.hpp"
#include "algorithms/shape/shape_model.hpp"
#include "tests/shape/bracket_scenes.hpp"

namespace facet::shape_detail {
namespace {

using testing::bracketScene;
using testing::bracketTemplate;

// The region a search gives a refinement from `pose`: the template's box placed there, 4 px wider.
cv::Rect regionAt(const ShapeModel& model, const Pose2D& pose) {
  const double w = model.templateSize.width, h = model.templateSize.height;
  const cv::Point2d centre =
      pose.map()({w / 2.0 - 0.5 - model.referencePoint.x, h / 2.0 - 0.5 - model.referencePoint.y});
  const cv::RotatedRect box(centre, cv::Size2f(static_cast<float>(w), static_cast<float>(h)),
                            static_cast<float>(pose.angle * 180.0 / std::numbers::pi));
  return box.boundingRect() + cv::Size(8, 8) - cv::Point(4, 4);
}

TEST(LeastSquaresRefinement, StartsSharingOneDetectionReachWhatEachReachesOnItsOwn) {
  const ShapeModel model = createShapeModel(bracketTemplate());
  // Two copies of the part, each with a start a few tenths of a pixel and degrees off.
  const std::vector<Pose2D> truths{{190.3, 230.6, 0.4, 1.0}, {450.7, 250.2, -2.1, 1.0}};
  const cv::Mat image = bracketScene({640, 480}, truths, 11);
  const std::vector<Pose2D> starts{{190.0, 231.0, 0.4 + 0.006, 1.0},
                                   {451.0, 250.0, -2.1 - 0.005, 1.0}};
  const cv::Rect both = regionAt(model, starts[0]) | regionAt(model, starts[1]);
  const LeastSquaresRefinement shared(image, model, both, Polarity::Use, starts, 0.02);
  // (With the edges fitted only near the first start's contour, the second part's pose moves by
  // 0.011 px and 2e-4 rad; sharing the detection moves it by 0.0004 px and 3e-5 rad.)
  for (std::size_t i = 0; i < starts.size(); ++i) {
    const LeastSquaresRefinement own(image, model, regionAt(model, starts[i]), Polarity::Use,
                                     {starts[i]}, 0.02);
    const Refined alone = own.refine(starts[i], false);
    const Refined together = shared.refine(starts[i], false);
    ASSERT_TRUE(alone.status.ok());
    ASSERT_TRUE(together.status.ok());
    EXPECT_LT(std::hypot(alone.pose.x - truths[i].x, alone.pose.y - truths[i].y), 0.03);
    EXPECT_LT(std::hypot(together.pose.x - alone.pose.x, together.pose.y - alone.pose.y), 0.003)
        << "part " << i;
    EXPECT_LT(std::abs(together.pose.angle - alone.pose.angle), 1e-4) << "part " << i;
  }
}

}  // namespace
}  // namespace facet::shape_detail
