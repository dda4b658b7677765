#include "algorithms/shape/pyramid_depth_check.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <numbers>

#include <opencv2/core/utility.hpp>
#include <opencv2/imgproc.hpp>

#include "algorithms/shape/find_shape_model.hpp"
#include "algorithms/shape/image_gradients.hpp"
#include "algorithms/shape/level_search.hpp"
#include "algorithms/shape/shape_similarity.hpp"

namespace facet {
namespace {

constexpr int kCopies = 8;
// A returned pose within kSamePlace of the copy's known one is the part. One farther away is
// another place that scores as high (a periodic pattern's next period: no depth tells them
// apart), unless the known pose scores higher by more than kScoreMargin: then the part was lost.
constexpr double kSamePlace = 1.0;  // pixels
constexpr double kScoreMargin = 0.01;

// Where copy k lands: its turn, radians, across the model's angles (uneven, so that no copy meets
// the angle steps as the template does), and its shift across a pixel of the top level, in
// eighths (x and y take every eighth once).
struct Placement {
  double angle;
  cv::Point2d shift;
};

Placement placement(const ShapeModel& model, int k) {
  const double full = 2.0 * std::numbers::pi;
  const double extent = std::min(model.angleExtent, full);
  const double angle = extent >= full - 1e-9 ? -std::numbers::pi + full * (k + 0.3) / kCopies
                                             : model.angleStart + extent * (k + 0.5) / kCopies;
  const double topPixel = std::ldexp(1.0, model.numLevels() - 1);
  return {
      angle,
      {topPixel * ((3 * k + 1) % kCopies) / kCopies, topPixel * ((5 * k + 2) % kCopies) / kCopies}};
}

// Whether the top level scores the copy's known pose at least the share of level 0's score
// (`level0Score`) that the search assumes of a part there (kTopFactor: it keeps top-level
// candidates from that share of the minimum score); one that keeps less would drop the part were
// it to score only the minimum at the end. The level's best over the 3x3 pixels around the pose,
// at the pose's angle: the loss asked about is that of the level's features under a turn, not of
// the angle grid's phase, which the search's looks absorb. The levels between are not held to
// their share (kMiddleFactor): a large template of a circuit board keeps less than 0.8 of it on
// levels that the search, looking around every candidate there, tracks the part through, and it
// would lose two of its six levels and run 7 times longer.
// `grey`: the copy as the search reads it (8-bit or float).
bool topLevelKeepsItsShare(const cv::Mat& grey, const ShapeModel& model, const Pose2D& truth,
                           double level0Score) {
  const int top = model.numLevels() - 1;
  if (top == 0) return true;
  cv::Mat level = grey;
  for (int l = 1; l <= top; ++l) cv::pyrDown(level, level);
  const double f = std::ldexp(1.0, -top);
  const cv::Point at(cvRound(truth.x * f), cvRound(truth.y * f));
  const int reach = static_cast<int>(std::ceil(model.radius() * f)) + 4;
  shape_detail::DirectionField field(level, model.minContrast);
  field.ensure(cv::Rect(at.x - reach, at.y - reach, 2 * reach + 1, 2 * reach + 1));
  const shape_detail::PosedPoints posed = shape_detail::posePoints(
      model.levels[static_cast<std::size_t>(top)].points, truth.angle, 1.0);
  const double best =
      std::max(0.0, shape_detail::bestScoreAround(field.directions(), posed, at, Polarity::Use, 0));
  return best >= shape_detail::kTopFactor * level0Score;
}

}  // namespace

int copiesLostBySearch(const cv::Mat& templateImage, const ShapeModel& model) {
  if (model.empty()) return 0;
  // A canvas around the region wide enough for the turned part and the shift: the image around
  // the region where it has one (copyMakeBorder reads beyond a region of a larger image), the
  // region's border repeated beyond.
  const cv::Point2d ref = model.referencePoint;
  const double nearestSide =
      std::min({ref.x, ref.y, templateImage.cols - 1 - ref.x, templateImage.rows - 1 - ref.y});
  const int margin = static_cast<int>(std::ceil(std::max(0.0, model.radius() - nearestSide))) +
                     (1 << (model.numLevels() - 1)) + 4;
  cv::Mat canvas;
  cv::copyMakeBorder(templateImage, canvas, margin, margin, margin, margin, cv::BORDER_REPLICATE);
  const cv::Point2d centre = ref + cv::Point2d(margin, margin);

  std::atomic<int> lost{0};
  cv::parallel_for_(cv::Range(0, kCopies), [&](const cv::Range& range) {
    for (int k = range.start; k < range.end; ++k) {
      const Placement p = placement(model, k);
      cv::Mat warp = cv::getRotationMatrix2D(centre, p.angle * 180.0 / std::numbers::pi, 1.0);
      warp.at<double>(0, 2) += p.shift.x;
      warp.at<double>(1, 2) += p.shift.y;
      cv::Mat copy;
      cv::warpAffine(canvas, copy, warp, canvas.size(), cv::INTER_CUBIC, cv::BORDER_REPLICATE);
      const Pose2D truth{centre.x + p.shift.x, centre.y + p.shift.y, p.angle, 1.0};

      FindParams find;  // the search's defaults, but for the finish: a pose within a pixel
      find.subpixel = SubpixelMode::Interpolation;
      find.threads = 1;
      const std::vector<ShapeMatch> matches = findShapeModel(copy, model, find);
      // The copy's grey as the search reads it (8-bit as it is, else on the 8-bit float scale),
      // from which its pyramid is built. The known pose's score, as the search scores an
      // interpolated pose.
      const cv::Mat grey = copy.depth() == CV_8U ? copy : shape_detail::toGreyFloat(copy);
      shape_detail::DirectionField field(grey, model.minContrast);
      field.ensureAll();
      const double truthScore =
          shape_detail::refinedScore(field.directions(), model, truth, Polarity::Use, 0);
      const bool found = !matches.empty() && std::hypot(matches.front().x - truth.x,
                                                        matches.front().y - truth.y) <= kSamePlace;
      const bool missed =
          !found && (matches.empty() ? truthScore >= find.minScore
                                     : truthScore > matches.front().score + kScoreMargin);
      if (missed || !topLevelKeepsItsShare(grey, model, truth, truthScore)) ++lost;
    }
  });
  return lost;
}

}  // namespace facet
